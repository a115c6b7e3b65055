#!/usr/bin/env bash
# The main job on the shipped default dataset (see README). $1: build folder.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
"$build_dir/tools/imscal" version
