#!/usr/bin/env bash
# partsim's main job on its built-in default: installs and builds what is missing (a build that
# is current costs about two seconds), then generates a cabinet (StorageFurniture), lets the flying
# gripper open one of its drawers with the heuristic solver (handle found in the cameras'
# segmented point clouds, grasped, pulled), records it from a three-quarter camera into
# out/demo/demo.mp4 (640x480, H.264) and reports success and the video's path. Extra arguments
# go to `partsim tasks demo` (e.g. --task door, --frames, --size 1280x960).
set -euo pipefail
cd "$(dirname "$0")/.."
# setup's time and the demo's own are printed apart (setup on a current build: under 3 s)
t0=$(date +%s.%N)
bash scripts/setup.sh
t1=$(date +%s.%N)
status=0
build/partsim tasks demo --task drawer --out out/demo "$@" || status=$?
t2=$(date +%s.%N)
awk -v a="$t0" -v b="$t1" -v c="$t2" \
  'BEGIN { printf "partsim run: setup %.1f s, demo %.1f s\n", b - a, c - b }' >&2
exit "$status"
