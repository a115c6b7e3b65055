#!/usr/bin/env bash
# Regenerates the UR10e campaign's records from its configuration:
#   scenario datasets/scenarios/ur10e-campaign.yaml (program datasets/programs/ur10e-campaign.yaml,
#            UR10e with stiff drives deviating from its nominal robot, navigation-grade IMS, seed 1)
# writes imu.csv, robot.csv and unit-calibration.yaml (the simulator's drawn scale factors and
# misalignments, biases set to zero: the lab calibration of this IMS unit) into OUT_DIR, and the
# simulator's truth into OUT_DIR/truth/ when OUT_DIR is not this folder. The records are not
# shipped (~10 MB; .gitignore): run this before `imscal run datasets/campaign-ur10e/run.yaml`.
# Usage: datasets/campaign-ur10e/regenerate.sh [BUILD_DIR] [OUT_DIR]   (OUT_DIR default: this folder)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
build_dir=${1:-$root/build}
out_dir=${2:-$here}
sim_dir=$(mktemp -d)
trap 'rm -rf "$sim_dir"' EXIT
"$build_dir/tools/imscal" simulate --scenario "$root/datasets/scenarios/ur10e-campaign.yaml" \
  --out "$sim_dir/sim" --force
mkdir -p "$out_dir"
cp "$sim_dir/sim/imu.csv" "$sim_dir/sim/robot.csv" "$out_dir/"
sed -E -e 's/^(  bias_deg_per_h: ).*/\1[0, 0, 0]/' -e 's/^(  bias_ug: ).*/\1[0, 0, 0]/' \
  "$sim_dir/sim/truth/sensor_errors.yaml" >"$out_dir/unit-calibration.yaml"
if [ "$out_dir" != "$here" ]; then
  rm -rf "$out_dir/truth"
  cp -r "$sim_dir/sim/truth" "$out_dir/truth"
fi
