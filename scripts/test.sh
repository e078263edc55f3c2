#!/usr/bin/env bash
# Installs what is needed, builds, and runs every test (gtest, rostest, launch checks) via ctest.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/install_deps.sh"
bash "$root/scripts/build.sh"
build="${SPINRADAR_BUILD_DIR:-$root/build}"
export PATH=/usr/bin:$PATH
export ROS_LOG_DIR="$build/ros_log" ROS_HOME="$build/ros_home"
if [ -f "$build/devel/setup.bash" ]; then set +u; source "$build/devel/setup.bash"; set -u; fi
cd "$build"
ctest --output-on-failure -j "${SPINRADAR_TEST_JOBS:-2}" "$@"
# ASan + UBSan over the low parts' unit tests and the reader fuzzers (SPINRADAR_SANITIZE=0 skips it;
# it never runs when ctest arguments select a subset).
if [ "${SPINRADAR_SANITIZE:-1}" != 0 ] && [ $# -eq 0 ]; then bash "$root/scripts/test_sanitize.sh"; fi
