#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build (clang, -O1) of the low parts (core,
# driver, io, features), their unit tests and the reader fuzzers (test/fuzz.cmake), then ctest.
# Run by scripts/test.sh after the main tests; alone: bash scripts/test_sanitize.sh [cmake args].
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SPINRADAR_SANITIZE_DIR:-${SPINRADAR_BUILD_DIR:-$root/build}-sanitize}"
export PATH=/usr/bin:$PATH
start=$(date +%s)
mkdir -p "$build"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_C_COMPILER=clang -DSPINRADAR_SANITIZE=ON -DSPINRADAR_WITH_ROS=OFF "$@" \
  > "$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
cmake --build "$build" -j "${SPINRADAR_JOBS:-$(nproc)}"
built=$(date +%s)
cd "$build"
# halt_on_error: any sanitizer report fails its test; leaks are not checked (OpenCV's caches).
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=0" UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
ctest --output-on-failure -j "${SPINRADAR_TEST_JOBS:-2}"
echo "sanitizer build: $((built - start)) s to build, $(( $(date +%s) - built )) s to test"
