#!/usr/bin/env bash
# First command of the README: installs the dependencies (Debian 12 packages), builds imscal in
# Release (with the Python module, build/python), puts the module on the user's Python path and
# runs the main job on the shipped default dataset.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh build
bash scripts/install-python.sh build
bash scripts/run-default.sh build
