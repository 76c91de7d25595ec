#!/usr/bin/env bash
# Checks an installed partsim from outside the source tree, as a user meets it:
#   bash scripts/install_smoke.sh PREFIX   after `cmake --install build --prefix PREFIX`
#   bash scripts/install_smoke.sh /usr     after `apt install ./build/partsim_*.deb`
# The command line from PATH, `import partsim` from any folder (and from PREFIX, not the build),
# a C++ program built against find_package(partsim), and the demo's video.
set -euo pipefail
src="$(cd "$(dirname "$0")/.." && pwd)"
prefix="$(cd "$1" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
export PATH="$prefix/bin:$PATH"
if [ "$prefix" != "/usr" ]; then
  export PYTHONPATH="$prefix/lib/python3/dist-packages"
  export LD_LIBRARY_PATH="$prefix/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi

echo "-- partsim on PATH: $(command -v partsim)"
[ "$(command -v partsim)" = "$prefix/bin/partsim" ] || { echo "partsim is not $prefix/bin/partsim"; exit 1; }
partsim --version

echo "-- import partsim from $work"
/usr/bin/python3 "$src/scripts/smoke_checks.py" scene "$prefix"

echo "-- a C++ program with find_package(partsim)"
cmake -S "$src/examples/cpp/hello_partsim" -B "$work/hello" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/hello" >/dev/null
"$work/hello/hello"

echo "-- partsim tasks demo from $work"
partsim tasks demo --size 320x240 --every 5 --out "$work/demo"
[ -s "$work/demo/demo.mp4" ] || { echo "no video at $work/demo/demo.mp4"; exit 1; }
echo "-- partsim learn (the installed Python package's learning protocol) from $work"
help="$(partsim learn --help)"
grep -q "partsim learn train" <<<"$help" || { echo "partsim learn --help failed: $help"; exit 1; }
/usr/bin/python3 -c "import partsim.learn.protocol as p, os, sys; \
assert os.path.realpath(p.__file__).startswith(os.path.realpath(sys.argv[1]) + '/'), p.__file__" \
  "$prefix"
# a short run with the project venv's interpreter (Gymnasium is not a Debian package), without
# PYTHONPATH: the installed command puts the installed package on the path itself
env -u PYTHONPATH PARTSIM_PYTHON="$src/.venv/bin/python" partsim learn train --task drawer \
  --obs mobility --train-objects 1 --test-objects 1 --steps 10 --num-envs 1 --warmup-steps 5 \
  --batch-size 4 --buffer-size 100 --hidden 8 --quiet --out "$work/run" >"$work/learn.txt"
grep -q '"env_steps": 10' "$work/learn.txt" || { echo "partsim learn train: $(cat "$work/learn.txt")"; exit 1; }
echo "-- an example that runs the command line finds the installed one, without PATH's help"
env PATH=/usr/bin:/bin "$src/.venv/bin/python" "$src/examples/cabinet_generator.py" \
  --out "$work/cabinet" >/dev/null
ls "$work/cabinet" | grep -q . || { echo "cabinet_generator wrote nothing"; exit 1; }
echo "-- the viewer's page, installed, found by the installed package (from $work)"
for page in index.html annotate.html annotate.js; do
  [ -f "$prefix/share/partsim/web/$page" ] || { echo "no $prefix/share/partsim/web/$page"; exit 1; }
done
/usr/bin/python3 "$src/scripts/smoke_checks.py" viewer "$prefix/share/partsim/web"
echo "install smoke test: all passed ($prefix)"
