#!/usr/bin/env bash
# Second command of the README, and what CI runs: installs the dependencies, builds with warnings
# as errors, runs every test; then builds again with AddressSanitizer and UndefinedBehaviorSanitizer
# and runs every test once more.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)
bash scripts/check-format.sh

echo "== Release build, warnings as errors =="
bash scripts/build.sh build-ci -DIMSCAL_WERROR=ON
ctest --test-dir build-ci --output-on-failure -j "$jobs" --timeout 900

echo "== ASan + UBSan build =="
bash scripts/build.sh build-asan -DIMSCAL_WERROR=ON -DIMSCAL_SANITIZE=ON \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DIMSCAL_BUILD_BENCH=OFF
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  IMSCAL_SANITIZED=1 ctest --test-dir build-asan --output-on-failure -j "$jobs" --timeout 1800

echo "== Fuzzing (libFuzzer, ASan + UBSan), ${FUZZ_SECONDS:-30} s per reader =="
FUZZ_SECONDS=${FUZZ_SECONDS:-30} bash scripts/fuzz.sh
