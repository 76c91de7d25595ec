#!/usr/bin/env bash
# Checks partsim's wheel as a pip user meets it: a new venv outside the tree, the wheel and its
# dependencies (at requirements.lock's versions) installed into it, then from another folder:
# `partsim` on PATH, `import partsim`, Gymnasium's registry, two examples, `partsim learn` and the
# viewer's page, all from the venv's site-packages and none from the build tree.
#   bash scripts/wheel_smoke.sh build/dist/partsim-*.whl
# The venv sees Debian's packages (--system-site-packages) as the project's does, so that
# `partsim learn` finds Debian's python3-torch; numpy and Gymnasium come from the lock.
set -euo pipefail
src="$(cd "$(dirname "$0")/.." && pwd)"
wheel="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
unset PYTHONPATH PARTSIM_PYTHON_DIR PARTSIM_CLI PARTSIM_WEB_DIR

echo "-- a new venv in $work/venv, the wheel and its dependencies from requirements.lock"
/usr/bin/python3 -m venv --system-site-packages "$work/venv"
py="$work/venv/bin/python"
# the lock's entries for the wheel's dependencies (numpy, gymnasium and gymnasium's own)
awk 'BEGIN { keep = 0 }
     /^[a-z0-9_.-]+==/ { split($1, a, "=="); keep = (a[1] ~ /^(numpy|gymnasium|cloudpickle|farama-notifications|typing-extensions)$/) }
     keep' "$src/requirements.lock" >"$work/deps.txt"
"$py" -m pip install --quiet --disable-pip-version-check --no-cache-dir --require-hashes --no-deps \
  -r "$work/deps.txt"
"$py" -m pip install --quiet --disable-pip-version-check --no-index --no-deps "$wheel"
# what the wheel and its dependencies need is there (Debian's own packages are not our concern)
if "$py" -m pip check | grep -E "^(partsim|numpy|gymnasium|cloudpickle|farama-notifications|typing-extensions) "; then
  echo "the wheel's dependencies are not satisfied"; exit 1
fi
export PATH="$work/venv/bin:$PATH"

echo "-- partsim on PATH: $(command -v partsim)"
[ "$(command -v partsim)" = "$work/venv/bin/partsim" ] || { echo "partsim is not the venv's"; exit 1; }
partsim --version

echo "-- import partsim, a scene, Gymnasium's registry and the viewer's page (from $work)"
"$py" "$src/scripts/smoke_checks.py" scene "$work/venv"
package="$("$py" -c 'import os, partsim; print(os.path.dirname(os.path.realpath(partsim.__file__)))')"
"$py" "$src/scripts/smoke_checks.py" viewer "$package/share/partsim/web"
"$py" - <<'PY'
import os
import gymnasium as gym
import partsim
package = os.path.dirname(os.path.realpath(partsim.__file__))
assert partsim.find_cli() == os.path.join(package, "bin", "partsim"), partsim.find_cli()
assert os.path.isfile(os.path.join(package, "_partsim.pyi")), "no type stubs in the wheel"
env = gym.make("partsim/OpenCabinetDrawer-v0", obs_mode="mobility")
obs, info = env.reset(seed=0)
obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
assert env.observation_space.contains(obs), obs
env.close()
print("gymnasium.make('partsim/OpenCabinetDrawer-v0'): a step, reward %.3f" % reward)
PY

echo "-- two examples run from $work (one of them runs the command line it finds)"
"$py" "$src/examples/hello_scene.py" --out "$work/hello" >/dev/null
"$py" "$src/examples/cabinet_generator.py" --out "$work/cabinet" >/dev/null
ls "$work/cabinet" | grep -q . || { echo "cabinet_generator wrote nothing"; exit 1; }

echo "-- partsim learn runs the venv's interpreter and package"
help="$(partsim learn --help)"
grep -q "partsim learn train" <<<"$help" || { echo "partsim learn --help failed: $help"; exit 1; }
partsim learn train --task drawer --obs mobility --train-objects 1 --test-objects 1 --steps 10 \
  --num-envs 1 --warmup-steps 5 --batch-size 4 --buffer-size 100 --hidden 8 --quiet \
  --out "$work/run" >"$work/learn.txt"
grep -q '"env_steps": 10' "$work/learn.txt" || { echo "partsim learn train: $(cat "$work/learn.txt")"; exit 1; }
"$py" -c "import partsim.learn.protocol as p, os, sys; \
assert os.path.realpath(p.__file__).startswith(os.path.realpath(sys.argv[1]) + '/'), p.__file__" \
  "$work/venv"
echo "wheel smoke test: all passed ($(basename "$wheel"))"
