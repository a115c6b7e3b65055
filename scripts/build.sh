#!/usr/bin/env bash
# Configures and builds imscal in Release into build/ (or the folder given as $1); further
# arguments go to CMake. Through ccache when it is installed (scripts/compiler-cache.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
shift || true
source scripts/compiler-cache.sh
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${compiler_cache_args[@]}" "$@" \
  >/dev/null
cmake --build "$build_dir" -j "$(nproc)"
