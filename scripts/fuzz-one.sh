#!/usr/bin/env bash
# Runs one libFuzzer target (called by scripts/fuzz.sh): $1 target (fuzz_<name>), $2 build folder,
# $3 seconds. Corpus: fuzz/corpus/<name>/ plus tests/data/fuzz_regressions/<name>/; new inputs go
# to <build>/corpus/<name>/. FUZZ_SEED fixes libFuzzer's random seed (CI: reproducible runs).
# On a crash: prints the log's tail, keeps the input in <build>/artifacts/ and exits 1; otherwise
# prints "<name> <executions>".
set -euo pipefail
target=$1 build=$2 seconds=$3
name=${target#fuzz_}
corpus=$build/corpus/$name
mkdir -p "$corpus" "$build/artifacts"
seeds=()
for dir in "fuzz/corpus/$name" "tests/data/fuzz_regressions/$name"; do
  [ -d "$dir" ] && seeds+=("$dir")
done
seed_option=()
[ -n "${FUZZ_SEED:-}" ] && seed_option=(-seed="$FUZZ_SEED")
log=$build/fuzz-$name.log
if ! ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  "$build/fuzz/$target" -max_total_time="$seconds" -max_len=65536 -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 "${seed_option[@]}" \
  -artifact_prefix="$build/artifacts/$name-" "$corpus" "${seeds[@]}" >"$log" 2>&1; then
  tail -60 "$log" >&2
  echo "FUZZ FAILURE in $name: input saved under $build/artifacts/$name-*" >&2
  exit 1
fi
runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
printf '%-16s %10s executions in %s s\n' "$name" "$runs" "$seconds"
