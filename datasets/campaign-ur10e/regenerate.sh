#!/usr/bin/env bash
# Regenerates the UR10e campaign's records from its configuration, as datasets/campaign/
# regenerate.sh does for the KR 16: scenario datasets/scenarios/ur10e-campaign.yaml (program
# datasets/programs/ur10e-campaign.yaml, a UR10e with stiff drives deviating from its nominal
# robot, navigation-grade IMS, seed 1) -> imu.csv, robot.csv and unit-calibration.yaml in OUT_DIR
# (the truth too when OUT_DIR is not this folder). The records are not shipped (~10 MB,
# .gitignore): run this before `imscal run datasets/campaign-ur10e/run.yaml`.
# Usage: datasets/campaign-ur10e/regenerate.sh [BUILD_DIR] [OUT_DIR]   (OUT_DIR default: this folder)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
CAMPAIGN_SCENARIO=ur10e-campaign CAMPAIGN_DIR=$here exec "$here/../campaign/regenerate.sh" "$@"
