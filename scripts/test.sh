#!/usr/bin/env bash
# Second command of the README, and what CI runs: installs the dependencies, checks the format,
# then two builds:
# 1. clang with -Wall -Wextra -Werror, AddressSanitizer and UndefinedBehaviorSanitizer, and
#    libFuzzer's coverage instrumentation: the whole test suite runs under the sanitizers (the
#    long figure tests shortened: IMSCAL_SANITIZED), the function-size check reads its compile
#    commands, then every fuzz target runs for FUZZ_SECONDS (default 10) from a fixed random seed
#    (FUZZ_SEED, default 1), so that a CI run can be repeated. Linked by lld. UBSan skips the Eigen
#    and Ceres headers' own code (cmake/ubsan-ignorelist.txt; ASan still checks every access
#    there, and Eigen's bounds asserts are on: no NDEBUG).
# 2. GCC Release (the build of setup.sh and bench/), warnings as errors, of the headline tests
#    only, which assert the figures the project is for at full size (scripts/test-release.sh).
# Budget: the whole run under 60 minutes on 2 cores.
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

echo "== Function size (clang-tidy readability-function-size) =="
bash scripts/check-function-size.sh build-ci

echo "== Fuzzing (libFuzzer, ASan + UBSan), ${FUZZ_SECONDS:-10} s per reader =="
FUZZ_SECONDS=${FUZZ_SECONDS:-10} FUZZ_SEED=${FUZZ_SEED:-1} bash scripts/fuzz.sh build-ci

echo "== Release (GCC, warnings as errors): the headline figures =="
bash scripts/test-release.sh build-release
