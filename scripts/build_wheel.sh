#!/usr/bin/env bash
# Builds partsim's wheel into build/dist from the build tree scripts/setup.sh keeps current:
# scikit-build-core (pyproject.toml) configures build/ for the wheel, builds the two targets it
# holds (nothing to compile when build/ is current) and installs component "wheel" into it.
# Usage: bash scripts/build_wheel.sh   (after bash scripts/setup.sh)
#
# `pip install .` from a checkout builds the same wheel in a build folder of its own (the whole
# C++ build, tens of minutes on two cores); reusing build/ costs seconds. The wheel's configure
# leaves its install prefix and Python hints in build/CMakeCache.txt, so the cache is put back
# afterwards: the next `cmake --build build` configures build/ as setup.sh did.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/CMakeCache.txt ] || { echo "build_wheel: no build/ yet: run bash scripts/setup.sh" >&2; exit 1; }
saved="$(mktemp)"
cp build/CMakeCache.txt "$saved"
restore() { cp "$saved" build/CMakeCache.txt && touch build/CMakeCache.txt && rm -f "$saved"; }
trap restore EXIT
rm -rf build/dist
CMAKE_GENERATOR="Unix Makefiles" CMAKE_BUILD_PARALLEL_LEVEL="${PARTSIM_JOBS:-2}" \
  .venv/bin/python -m pip wheel --quiet --disable-pip-version-check --no-build-isolation --no-deps \
  --config-settings=build-dir=build -w build/dist .
echo "partsim: built $(ls build/dist/partsim-*.whl)"
