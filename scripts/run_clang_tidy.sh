#!/usr/bin/env bash
# Runs clang-tidy with the committed .clang-tidy on partsim's own sources (src/, not tests or
# third-party headers) from the build's compile_commands.json; any finding fails (the checks are
# errors). Usage: bash scripts/run_clang_tidy.sh [build dir (default build)]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
if [ ! -f "$build/compile_commands.json" ]; then
  echo "run_clang_tidy: no $build/compile_commands.json (configure with CMake first)" >&2
  exit 1
fi
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
status=0
run-clang-tidy -p "$build" -j"${PARTSIM_JOBS:-2}" -quiet "$PWD/src/" 2>&1 |
  sed -e 's/\x1b\[[0-9;]*m//g' >"$log" || status=$?
findings=$(grep -cE "(warning|error): .*\[[a-z]+-" "$log" || true)
if [ "$status" -ne 0 ] || [ "$findings" -ne 0 ]; then
  grep -E "(warning|error): " -A3 "$log" | head -200
  echo "clang-tidy: $findings finding(s) in src/ (exit $status)"
  exit 1
fi
echo "clang-tidy: no findings in $(grep -c '"file"' "$build/compile_commands.json") compile commands' src/ files"
