#!/usr/bin/env bash
# Builds imscal (Release) and runs every benchmark and side-by-side comparison, printing the
# figures quoted in docs/results.md. Benchmarks report CPU time as well as wall time: on a
# loaded machine, quote ratios measured in the same run.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
bash scripts/build.sh "$build_dir"
for bench in "$build_dir"/bench/bench_*; do
  [ -x "$bench" ] || continue
  echo "== $bench"
  "$bench" --benchmark_counters_tabular=true
done
echo "== bench/compare_arx_numpy.py (numpy lstsq vs imscal, same run)"
/usr/bin/python3 bench/compare_arx_numpy.py "$build_dir"
