#!/usr/bin/env bash
# Fails when a function of the library or the command line is longer than LINES (default 80)
# lines of body (clang-tidy's readability-function-size, LineThreshold) and is not listed in
# scripts/function-size-exceptions.txt, or when a listed function is no longer that long: the
# list of exceptions only shrinks (remove the line when a function has been split). $1: a build
# folder with compile_commands.json. Only .cpp files: a header's inline functions are small.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:?usage: check-function-size.sh BUILD_DIR}
lines=${FUNCTION_SIZE_LINES:-80}
exceptions=scripts/function-size-exceptions.txt
[ -f "$build/compile_commands.json" ] ||
  { echo "check-function-size: $build/compile_commands.json missing" >&2; exit 2; }
config="{CheckOptions: [{key: readability-function-size.LineThreshold, value: $lines}]}"
found=$(mktemp)
trap 'rm -f "$found"' EXIT
git ls-files 'core/*.cpp' 'ims/*.cpp' 'robot/*.cpp' 'calib/*.cpp' 'ident/*.cpp' 'sim/*.cpp' 'eval/*.cpp' \
  'tools/*.cpp' 'online/*.cpp' |
  xargs -P "$(nproc)" -n 4 clang-tidy -p "$build" --quiet --checks='-*,readability-function-size' \
    --config="$config" 2>/dev/null |
  sed -n "s|^$PWD/\([^:]*\):[0-9]*:[0-9]*: warning: function '\([^']*\)' exceeds.*|\1 \2|p" |
  sort >"$found" || true
status=0
new=$(comm -23 "$found" <(grep -v '^#' "$exceptions" | sort))
gone=$(comm -13 "$found" <(grep -v '^#' "$exceptions" | sort))
if [ -n "$new" ]; then
  echo "functions over $lines lines (split them; the exceptions list only shrinks):"
  echo "$new" | sed 's/^/  /'
  status=1
fi
if [ -n "$gone" ]; then
  echo "no longer over $lines lines: remove these lines from $exceptions:"
  echo "$gone" | sed 's/^/  /'
  status=1
fi
[ "$status" -eq 0 ] && echo "function size: $(wc -l <"$found") listed exceptions over $lines lines, no new one"
exit "$status"
