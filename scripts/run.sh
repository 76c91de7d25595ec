#!/usr/bin/env bash
# partsim's main job on its built-in default: installs and builds what is missing (a build that
# is current costs about a second), then generates a cabinet (StorageFurniture), lets the flying
# gripper open one of its drawers with the heuristic solver (handle found in the cameras'
# segmented point clouds, grasped, pulled), records it from a three-quarter camera into
# out/demo/demo.mp4 (640x480, H.264) and reports success and the video's path. Extra arguments
# go to `partsim tasks demo` (e.g. --task door, --frames, --size 1280x960).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
build/partsim tasks demo --task drawer --out out/demo "$@"
