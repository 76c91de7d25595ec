#!/usr/bin/env bash
# Installs, builds (from scratch on a clean checkout, else what changed) and runs the whole test
# suite: GoogleTest through CTest, pytest, the source format check, the installed partsim (a
# temporary prefix and the Debian package, each used from outside the tree), the wheel (installed
# into a new venv) and the URDF and OBJ fuzzers under AddressSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# the packages that setup installed (requirements.lock's pins, Debian's torch and websocket) must be
# there: the Python tests that skip without them fail instead (tests/python/conftest.py, require)
export PARTSIM_REQUIRE_PINNED="${PARTSIM_REQUIRE_PINNED:-1}"

echo "== source format (clang-format)"
bash scripts/check_format.sh

echo "== clang-tidy (.clang-tidy's checks on src/)"
bash scripts/run_clang_tidy.sh build

echo "== Node.js client for the rosbridge test: roslib and ws from npm into build/node"
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  # Debian's nodejs does not ship npm; NodeSource's nodejs does (and conflicts with Debian's npm)
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends nodejs npm
fi
npm install --prefix build/node --no-audit --no-fund roslib@^2.1.0 ws@^8

echo "== Chromium for the viewer's browser tests (headless, driven by puppeteer-core from web/)"
if ! command -v chromium >/dev/null; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends chromium
fi

echo "== physics alone: core and physics built and tested without the layers above (build-physics/)"
if [ ! -f build-physics/CMakeCache.txt ]; then
  cmake -S . -B build-physics -DCMAKE_BUILD_TYPE=Release -DPARTSIM_PHYSICS_ONLY=ON >/dev/null
fi
cmake --build build-physics -j"${PARTSIM_JOBS:-2}"
ctest --test-dir build-physics --output-on-failure -j2

echo "== C++ tests (ctest)"
ctest --test-dir build --output-on-failure -j2

echo "== Python tests (pytest)"
PARTSIM_PYTHON_DIR="$PWD/build/python" .venv/bin/python -m pytest tests/python -q

echo "== install: cmake --install into a temporary prefix, then the Debian package; each checked from outside the tree"
prefix="$(mktemp -d)"
cmake --install build --prefix "$prefix" >/dev/null
bash scripts/install_smoke.sh "$prefix"
rm -rf "$prefix"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
if dpkg-query -W -f='${Status}' partsim 2>/dev/null | grep -q "install ok installed"; then
  echo "partsim is installed from a package already: not replacing it; the .deb is not checked"
else
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q ./build/partsim_*.deb
  status=0
  bash scripts/install_smoke.sh /usr || status=$?
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get remove -y -q partsim
  [ "$status" -eq 0 ]
fi

echo "== the wheel: built by scikit-build-core over build/, installed into a new venv outside the tree"
bash scripts/build_wheel.sh
bash scripts/wheel_smoke.sh build/dist/partsim-*.whl

echo "== URDF and OBJ fuzzers (libFuzzer + AddressSanitizer)"
bash scripts/run_fuzz.sh
