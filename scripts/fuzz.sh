#!/usr/bin/env bash
# Runs every libFuzzer target (fuzz/fuzz_*.cpp) for FUZZ_SECONDS (default 60) each, as many at once
# as there are cores, under AddressSanitizer and UndefinedBehaviorSanitizer. $1: a build folder
# configured with -DIMSCAL_FUZZ=ON (CI passes its one clang build); without it, build-fuzz/ is
# configured with clang. Prints the executions per target. A crash fails the script with the input
# saved in <build>/artifacts/: once fixed, copy it to tests/data/fuzz_regressions/<target>/
# (tests/core/test_fuzz_regressions.cpp replays every such file).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-60}
build=${1:-build-fuzz}
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DIMSCAL_FUZZ=ON -DIMSCAL_SANITIZE=ON \
    -DIMSCAL_BUILD_TESTS=OFF -DIMSCAL_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" >/dev/null
fi
grep -q '^IMSCAL_FUZZ:BOOL=ON' "$build/CMakeCache.txt" ||
  { echo "fuzz.sh: $build is not configured with -DIMSCAL_FUZZ=ON" >&2; exit 2; }
targets=$(cd fuzz && ls fuzz_*.cpp | sed 's/\.cpp$//')
ninja -C "$build" -j "$(nproc)" $targets
echo "== fuzzing $(echo $targets | wc -w) readers for ${seconds} s each, $(nproc) at once =="
summary=$(printf '%s\n' $targets |
  xargs -P "$(nproc)" -I{} bash scripts/fuzz-one.sh {} "$build" "$seconds")
echo "== fuzzing summary =="
printf '%s\n' "$summary"
