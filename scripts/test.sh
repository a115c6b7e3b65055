#!/usr/bin/env bash
# Second command of the README, and what CI runs: installs the dependencies, checks the format,
# then ONE build serves every check: clang with -Wall -Wextra -Werror, AddressSanitizer and
# UndefinedBehaviorSanitizer, and libFuzzer's coverage instrumentation. The whole test suite runs
# under the sanitizers, then every fuzz target runs for FUZZ_SECONDS (default 10: the CI budget
# is 25 min on 2 cores, and a slow CI machine took 32 min with 20 s) from a fixed random seed
# (FUZZ_SEED, default 1), so that a CI run can be repeated. Linked by lld (326 links: ~0.2 s
# each instead of ~0.5 s with GNU ld). UBSan skips the Eigen and Ceres headers' own code
# (cmake/ubsan-ignorelist.txt; ASan still checks every access there, and Eigen's bounds asserts
# are on: no NDEBUG): their checks kept those small functions out of line at -O1, and a sanitized
# calibration test ran 4.7x slower for it. (Release builds are for setup.sh and bench/.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)
bash scripts/check-format.sh

echo "== Build: clang, warnings as errors, ASan + UBSan, libFuzzer coverage =="
CC=clang CXX=clang++ bash scripts/build.sh build-ci -DIMSCAL_WERROR=ON -DIMSCAL_SANITIZE=ON \
  -DIMSCAL_FUZZ=ON -DIMSCAL_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld

echo "== Every test under ASan + UBSan =="
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  IMSCAL_SANITIZED=1 ctest --test-dir build-ci --output-on-failure -j "$jobs" --timeout 1800

echo "== Fuzzing (libFuzzer, ASan + UBSan), ${FUZZ_SECONDS:-10} s per reader =="
FUZZ_SECONDS=${FUZZ_SECONDS:-10} FUZZ_SEED=${FUZZ_SEED:-1} bash scripts/fuzz.sh build-ci
