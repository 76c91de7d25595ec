#!/usr/bin/env bash
# partsim's main job on its built-in default: installs, builds, then simulates the embedded
# cabinet (a drawer and a door driven open) and writes the joint trajectory to out/trajectory.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
mkdir -p out
build/partsim info
build/partsim simulate --steps 1500 --out out/trajectory.csv "$@"
