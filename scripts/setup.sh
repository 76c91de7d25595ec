#!/usr/bin/env bash
# Installs partsim's build dependencies from Debian 12 and builds everything into build/.
# Usage: bash scripts/setup.sh   (as root, or with sudo available)
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake git pkg-config
  libmujoco-dev libqhull-dev libeigen3-dev libassimp-dev libtinyxml2-dev nlohmann-json3-dev
  pybind11-dev python3-dev python3-numpy python3-pytest
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev clang-format
  libegl-dev libegl-mesa0 libgl1-mesa-dri libopengl-dev libembree-dev libpng-dev
  libbullet-extras-dev libjpeg-dev libompl-dev
  libwebsocketpp-dev libboost-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "partsim setup: installing ${missing[*]}"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# /usr/bin/python3 is Debian's interpreter: the one that sees python3-numpy and pybind11
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3
cmake --build build -j"${PARTSIM_JOBS:-2}"
