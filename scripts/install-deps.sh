#!/usr/bin/env bash
# Installs every build, test and report dependency of imscal from Debian 12 packages.
# Idempotent: re-running it on a machine that has everything is quick.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git ccache
  libeigen3-dev libceres-dev libsuitesparse-dev libgeographiclib-dev liborocos-kdl-dev liburdfdom-dev liburdfdom-headers-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libfmt-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev libopencv-calib3d-dev libtinyxml2-dev
  protobuf-compiler libprotobuf-dev
  gnuplot-nox python3 python3-numpy python3-dev pybind11-dev python3-pybind11 python3-pytest
  python3-matplotlib clang-format clang-tidy clang lld chromium
  snakemake slurm-wlm munge
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
