#!/usr/bin/env bash
# Installs the Debian packages dgmm needs that are not installed yet (apt-get; needs root or sudo).
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libeigen3-dev libceres-dev libhdf5-dev libvtk9-dev libmujoco-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  xvfb xauth python3 python3-dev python3-numpy python3-h5py python3-sklearn python3-pytest pybind11-dev
  clang-14 libclang-rt-14-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#packages[@]} Debian packages present"
  exit 0
fi
echo "deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
