#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang, AddressSanitizer and UndefinedBehaviorSanitizer
# and runs each for FUZZ_SECONDS (default 60) from its seed corpus (fuzz/corpus/<target>/, plus
# the regression inputs in tests/data/fuzz_regressions/<target>/). Prints the executions per
# target; a crash stops the script with the crashing input saved in build-fuzz/artifacts/ (copy it
# to tests/data/fuzz_regressions/<target>/ once fixed: tests/core/test_fuzz_regressions.cpp
# replays every such file).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-60}
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DIMSCAL_FUZZ=ON -DIMSCAL_SANITIZE=ON \
  -DIMSCAL_BUILD_TESTS=OFF -DIMSCAL_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" >/dev/null
targets=$(cd fuzz && ls fuzz_*.cpp | sed 's/\.cpp$//')
ninja -C build-fuzz -j "$(nproc)" $targets
mkdir -p build-fuzz/artifacts
summary=""
for target in $targets; do
  name=${target#fuzz_}
  corpus=build-fuzz/corpus/$name
  mkdir -p "$corpus"
  seeds=()
  for dir in "fuzz/corpus/$name" "tests/data/fuzz_regressions/$name"; do
    [ -d "$dir" ] && seeds+=("$dir")
  done
  log=build-fuzz/$name.log
  echo "== fuzzing $name for ${seconds} s =="
  if ! ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "build-fuzz/fuzz/$target" -max_total_time="$seconds" -max_len=65536 -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="build-fuzz/artifacts/$name-" \
    "$corpus" "${seeds[@]}" >"$log" 2>&1; then
    tail -60 "$log"
    echo "FUZZ FAILURE in $name: input saved under build-fuzz/artifacts/$name-*" >&2
    exit 1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  summary+=$(printf '%-16s %10s executions in %s s\n' "$name" "$runs" "$seconds")$'\n'
done
echo "== fuzzing summary =="
printf '%s' "$summary"
