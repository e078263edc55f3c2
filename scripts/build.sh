#!/usr/bin/env bash
# Configures and builds spinradar (core, simulator, CLI and, with catkin present, the nodelets)
# into build/. Usage: scripts/build.sh [extra cmake args]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH=/usr/bin:$PATH   # Debian's python3 has the ROS modules; a pyenv one does not
build="${SPINRADAR_BUILD_DIR:-$root/build}"
mkdir -p "$build"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
  -DCATKIN_DEVEL_PREFIX="$build/devel" -DCATKIN_ENABLE_TESTING=ON "$@" > "$build/configure.log" 2>&1 \
  || { cat "$build/configure.log"; exit 1; }
cmake --build "$build" -j "${SPINRADAR_JOBS:-$(nproc)}"
