#!/usr/bin/env bash
# Regenerates the shipped default campaign bit for bit from its configuration:
#   scenario datasets/scenarios/campaign.yaml (program datasets/programs/campaign.yaml, KR 16
#            with stiff drives, navigation-grade IMS, seed 1)
# writes imu.csv, robot.csv and unit-calibration.yaml (the simulator's drawn scale factors and
# misalignments, biases set to zero: the lab calibration of this IMS unit) into OUT_DIR, and the
# simulator's truth into OUT_DIR/truth/ (not shipped: ~30 MB).
# Usage: datasets/campaign/regenerate.sh [BUILD_DIR] [OUT_DIR]   (OUT_DIR default: this folder)
# CAMPAIGN_SCENARIO and CAMPAIGN_DIR name another scenario of datasets/scenarios/ and its
# campaign folder (datasets/campaign-ur10e/regenerate.sh).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build_dir=${1:-$root/build}
campaign_dir=${CAMPAIGN_DIR:-$here}
out_dir=${2:-$campaign_dir}
sim_dir=$(mktemp -d)
trap 'rm -rf "$sim_dir"' EXIT
scenario=${CAMPAIGN_SCENARIO:-campaign}
"$build_dir/tools/imscal" simulate --scenario "$root/datasets/scenarios/$scenario.yaml" \
  --out "$sim_dir/sim" --force
mkdir -p "$out_dir"
cp "$sim_dir/sim/imu.csv" "$sim_dir/sim/robot.csv" "$out_dir/"
sed -E -e 's/^(  bias_deg_per_h: ).*/\1[0, 0, 0]/' -e 's/^(  bias_ug: ).*/\1[0, 0, 0]/' \
  "$sim_dir/sim/truth/sensor_errors.yaml" >"$out_dir/unit-calibration.yaml"
if [ "$out_dir" != "$campaign_dir" ]; then
  rm -rf "$out_dir/truth"
  cp -r "$sim_dir/sim/truth" "$out_dir/truth"
fi
