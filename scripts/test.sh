#!/usr/bin/env bash
# Installs, builds from scratch and runs the whole test suite: GoogleTest through CTest, pytest,
# the source format check, and the URDF fuzzer under AddressSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

echo "== source format (clang-format)"
bash scripts/check_format.sh

echo "== Node.js client for the rosbridge test: roslib and ws from npm into build/node"
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  # Debian's nodejs does not ship npm; NodeSource's nodejs does (and conflicts with Debian's npm)
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends nodejs npm
fi
npm install --prefix build/node --no-audit --no-fund roslib@^2.1.0 ws@^8

echo "== C++ tests (ctest)"
ctest --test-dir build --output-on-failure -j2

echo "== Python tests (pytest)"
PARTSIM_PYTHON_DIR="$PWD/build/python" /usr/bin/python3 -m pytest tests/python -q

echo "== URDF fuzzer (libFuzzer + AddressSanitizer)"
bash scripts/run_fuzz.sh
