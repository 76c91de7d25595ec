#!/usr/bin/env bash
# partsim's main job on its built-in default: installs, builds, then generates a cabinet
# (StorageFurniture), lets the flying gripper open one of its drawers with the heuristic solver
# (handle found in the cameras' segmented point clouds, grasped, pulled), writes the front
# camera's frames to out/demo/ and reports success. Extra arguments go to `partsim tasks demo`
# (e.g. --task door).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
rm -rf out/demo
mkdir -p out/demo
build/partsim tasks demo --task drawer --out out/demo "$@"
