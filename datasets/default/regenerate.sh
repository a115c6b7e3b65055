#!/usr/bin/env bash
# Regenerates the shipped default campaign bit for bit from its configuration:
#   motion  datasets/motions/pauses-60s.yaml   (60 s robot-like moves, a rest at least every 5 s)
#   sensor  datasets/sensors/navigation-grade.yaml (RLG + servo accelerometers)
#   site    48.78 N, 9.18 E, 300 m (WGS84)
#   IMS rate 1000 Hz, seed 1
# Usage: datasets/default/regenerate.sh [BUILD_DIR] [OUT_DIR]   (OUT_DIR default: this folder)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build_dir=${1:-$root/build}
out_dir=${2:-$here}
"$build_dir/tools/imscal" synthesize --motion "$root/datasets/motions/pauses-60s.yaml" \
  --sensor "$root/datasets/sensors/navigation-grade.yaml" --site 48.78,9.18,300 \
  --rate-hz 1000 --seed 1 --imu-format imsb --out "$out_dir" --force
