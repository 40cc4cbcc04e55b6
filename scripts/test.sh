#!/usr/bin/env bash
# Installs dependencies, builds (Release, -Wall -Wextra), runs every test through ctest, then
# rebuilds the import/bad-input/loader tests under ASan+UBSan and runs them, then builds the
# consumer sample against the installed package.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DGIBAKE_BUILD_TESTS=ON -DGIBAKE_BUILD_BENCH=ON
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGIBAKE_SANITIZE=ON \
  -DGIBAKE_BUILD_BENCH=OFF
cmake --build build-asan -j "$jobs" --target gibake_sanitize_tests
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -L sanitize

if [ -x scripts/consumer.sh ]; then scripts/consumer.sh; fi
echo "test.sh: all tests passed"
