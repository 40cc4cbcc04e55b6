#!/usr/bin/env bash
# Installs every build, test and runtime dependency from Debian 12 packages. Idempotent.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git python3 clang libclang-rt-14-dev
  libembree-dev libtbb-dev
  libopenvdb-dev libboost-iostreams-dev libblosc-dev libopenvdb-tools python3-openvdb
  libopenexr-dev libimath-dev
  libtinygltf-dev libstb-dev nlohmann-json3-dev chromium
  libcgal-dev libgmp-dev libmpfr-dev
  libdraco-dev
  libvulkan-dev vulkan-tools glslc mesa-vulkan-drivers vulkan-validationlayers
  libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev libxxhash-dev libdeflate-dev
  slurmctld slurmd slurm-client munge
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: installed ${#missing[@]} packages"
