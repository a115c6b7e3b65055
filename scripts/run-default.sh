#!/usr/bin/env bash
# The main job on the shipped default dataset (README, "The main job"). $1: build folder.
# The main command's run goes to out/campaign/ (report: out/campaign/report/report.html); the
# further examples to out/default/.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
imscal="$build_dir/tools/imscal"
out=out/default
mkdir -p "$out"

echo "== The main command: imscal run on the shipped default campaign (datasets/campaign/)"
# Raw IMS record and robot log -> calibrate -> identify -> verify (ISO 9283) -> diagnose ->
# report. A second run with nothing changed skips every stage.
"$imscal" run datasets/campaign/run.yaml --out out/campaign
echo "Report: out/campaign/report/report.html; parameter tables: out/campaign/identify/"
(cd datasets/campaign && sha256sum --quiet -c SHA256SUMS)

echo "== Further examples"
echo "== 1. Real ring-laser-gyro record: levelling and gyrocompassing, per 5-minute window"
"$imscal" align --input tests/data/real/rlg-static/lasergyro.imu --window-s 300 \
  --out "$out/align-rlg.json"

echo "== 2. Shipped motion record (datasets/default): the raw file is what its configuration regenerates, bit for bit"
datasets/default/regenerate.sh "$build_dir" "$out/regenerated" >/dev/null
cmp datasets/default/imu.imsb "$out/regenerated/imu.imsb"
(cd datasets/default && sha256sum --quiet -c imu.imsb.sha256)
echo "datasets/default/imu.imsb regenerated identically (sha256 checked)"

echo "== 3. Error correction, alignment, mechanization, zero-velocity smoothing"
# Roll and pitch by levelling on the first rest; the heading from an external reference (the
# motion starts facing North): seconds of gyrocompassing would give it only to degrees.
"$imscal" mechanize --input datasets/default/imu.imsb \
  --sensor-errors datasets/default/unit-calibration.yaml --align-s 1.9 --heading-deg 0 \
  --smooth datasets/sensors/navigation-grade.yaml --out "$out/nav" --force

echo "== 4. Smoothed trajectory against the truth"
"$imscal" compare --estimate "$out/nav/trajectory.csv" \
  --reference "$out/regenerated/truth/trajectory.csv" --json "$out/nav/errors.json"
echo "== 5. The paper's test on the simulated robot: seed-line (robot log, raw IMS file, truth)"
"$imscal" simulate --scenario seed-line --out "$out/seed-line" --force
echo "Results in $out/: align-rlg.json, nav/ (trajectory with 1-sigma, errors.json), seed-line/"
