#!/usr/bin/env bash
# Installs partsim's build dependencies from Debian 12 and builds everything into build/.
# Usage: bash scripts/setup.sh   (as root, or with sudo available)
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake git pkg-config
  libqhull-dev libeigen3-dev libassimp-dev libtinyxml2-dev nlohmann-json3-dev
  pybind11-dev python3-dev python3-venv python3-numpy python3-pytest
  # the SAPIEN-style examples save pictures and build rotations as SAPIEN's tutorials do
  python3-pil python3-transforms3d
  # PyTorch (CPU) for partsim.vision's torch datasets, learning on the tasks and the perception
  # baselines (torchvision: Mask R-CNN, ResNet-50; scipy: Hungarian matching); matplotlib for
  # the learning curves
  python3-torch python3-torchvision python3-scipy python3-matplotlib
  # an optimised BLAS for it (Debian's torch calls the system BLAS: the reference one is ~15x
  # slower at the networks' matrix products)
  libopenblas0-openmp
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev clang-format clang-tidy
  libegl-dev libegl-mesa0 libgl1-mesa-dri libopengl-dev libembree-dev libpng-dev
  libbullet-extras-dev libjpeg-dev libompl-dev
  libwebsocketpp-dev libboost-dev
  # the viewer's Python tests talk to its WebSocket with websocket-client
  python3-websocket
  # MP4 videos of the demo and of VideoWriter (H.264 through Debian's libx264)
  libavformat-dev libavcodec-dev libavutil-dev libswscale-dev
)
# native ROS 1 (optional build; PARTSIM_NO_ROS1=1 leaves it out): roscpp, actionlib, the message
# packages with their definitions and Debian's message generators; rospy, rostopic and
# rosmaster for the tests
if [ "${PARTSIM_NO_ROS1:-0}" != "1" ]; then
  PACKAGES+=(
    libroscpp-dev libactionlib-dev libactionlib-msgs-dev libstd-msgs-dev libstd-srvs-dev
    libsensor-msgs-dev libtrajectory-msgs-dev libgeometry-msgs-dev libtf2-msgs-dev
    libros-rosgraph-msgs-dev ros-message-generation python3-genmsg python3-gencpp python3-genpy
    ros-std-msgs ros-std-srvs ros-sensor-msgs ros-trajectory-msgs ros-geometry-msgs
    ros-actionlib-msgs
    python3-rospy python3-rostopic python3-actionlib python3-rosmaster python3-std-msgs
    python3-std-srvs python3-sensor-msgs python3-trajectory-msgs python3-geometry-msgs
    python3-rosgraph-msgs python3-tf2-msgs python3-actionlib-msgs
  )
fi

# one dpkg-query for all of them (one call per package took 4 s of every run.sh)
declare -A installed=()
while read -r p; do
  installed[$p]=1
done < <(dpkg-query -W -f='${Package} ${Status}\n' "${PACKAGES[@]}" 2>/dev/null |
  awk '$2 == "install" && $3 == "ok" && $4 == "installed" { print $1 }' || true)
missing=()
for p in "${PACKAGES[@]}"; do
  [ -n "${installed[$p]:-}" ] || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "partsim setup: installing ${missing[*]}"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The project's Python environment: a venv made from Debian's /usr/bin/python3 that also sees
# Debian's packages (numpy, pytest, torch, rospy), with requirements.lock's packages from PyPI:
# MuJoCo among them, whose library and headers the build takes (cmake/mujoco.cmake). The lock is
# installed again whenever it changed.
bash scripts/setup_venv.sh

# Configure once: afterwards `cmake --build` configures again by itself when a CMakeLists.txt,
# a globbed folder or a ROS 1 message definition changes, so a build that is current costs a
# second. A build folder configured before the venv (Debian's MuJoCo) is configured again.
if [ ! -f build/CMakeCache.txt ] || [ ! -f build/Makefile ] ||
    ! grep -q "^PARTSIM_MUJOCO_DIR:" build/CMakeCache.txt; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE="$PWD/.venv/bin/python"
fi
cmake --build build -j"${PARTSIM_JOBS:-2}"

# the viewer's web page (docs/viewer.md): Node.js and npm from Debian when there is no node yet,
# then three.js, roslib and esbuild from npm (web/package-lock.json) bundled into build/web
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  # Debian's nodejs does not ship npm; NodeSource's nodejs does (and conflicts with Debian's npm)
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends nodejs npm
fi
# only when its inputs changed: a stamp of their contents in build/ (the bundle took 6 s
# and, being new, made the Debian package below be built again on every run)
web_inputs() {
  { find web/src web/index.html web/viewer.css web/annotate.html web/annotate.css \
    web/package.json web/package-lock.json \
    web/node_modules/.package-lock.json scripts/build_web.sh -type f -print0 2>/dev/null || true; } |
    sort -z | xargs -0 -r sha256sum
}
web_stamp=build/.partsim-web-inputs.sha256  # outside build/web, which is installed as it is
if [ -f build/web/viewer.js ] && [ -f build/web/index.html ] && [ -f build/web/viewer.css ] &&
    [ -f build/web/annotate.js ] && [ -f build/web/annotate.html ] &&
    [ -f web/node_modules/.package-lock.json ] && [ -f "$web_stamp" ] &&
    [ "$(web_inputs)" = "$(cat "$web_stamp")" ]; then
  echo "partsim setup: web page in build/web is current"
else
  rm -f "$web_stamp"
  bash scripts/build_web.sh
  web_inputs >"$web_stamp"
fi

# the Debian package (build/partsim_<version>_<arch>.deb), again only when something in it changed
deb=$(ls build/partsim_*.deb 2>/dev/null | head -n 1 || true)
if [ -z "$deb" ] || [ -n "$(find build/partsim build/libpartsim.so* build/python/partsim build/web include \
    -newer "$deb" -print -quit 2>/dev/null)" ]; then
  (cd build && cpack -G DEB >/dev/null) && echo "partsim setup: built $(ls build/partsim_*.deb)"
fi
