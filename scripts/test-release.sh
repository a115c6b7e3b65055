#!/usr/bin/env bash
# CI's Release stage, after the sanitizer suite: a GCC Release build (warnings as errors, the
# compiler and flags of setup.sh and bench/) of `imscal` and the headline tests only, which then
# assert the figures the project is for at full size (the verification on the paper's line and
# the ISO 9283 set, the two-session identification, the gap harness, `imscal run` through the
# chain, the main job; under the sanitizers they run shortened and assert less), and the tests
# that need Release speed (label `release`: the plant population, the workflows locally and
# through a single-node Slurm, and the Python module's pytest). The figures the
# tests record are written to <build>/results.md (scripts/results.py), stamped with commit and
# machine. $1: the build folder (default build-release).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-release}
jobs=$(nproc)
source scripts/compiler-cache.sh
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DIMSCAL_WERROR=ON \
  -DIMSCAL_BUILD_BENCH=OFF "${compiler_cache_args[@]}" >/dev/null
cmake --build "$build" -j "$jobs" --target headline_tests
rm -rf "$build/test-results"
status=0
ctest --test-dir "$build" -L "headline|release" --output-on-failure -j "$jobs" --timeout 2400 || status=$?
python3 scripts/results.py "$build/test-results" "$build/results.md" || status=1
exit "$status"
