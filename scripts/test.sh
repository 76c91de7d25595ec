#!/usr/bin/env bash
# Installs, builds from scratch and runs the whole test suite: GoogleTest through CTest, pytest,
# the source format check, and the URDF fuzzer under AddressSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

echo "== source format (clang-format)"
bash scripts/check_format.sh

echo "== C++ tests (ctest)"
ctest --test-dir build --output-on-failure -j2

echo "== Python tests (pytest)"
PARTSIM_PYTHON_DIR="$PWD/build/python" /usr/bin/python3 -m pytest tests/python -q

echo "== URDF fuzzer (libFuzzer + AddressSanitizer)"
bash scripts/run_fuzz.sh
