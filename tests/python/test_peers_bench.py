"""bench/peers/peers_bench.py keeps working: one tiny run (1 repetition of 20 steps per scene) of
every engine that is installed, read back from its --json file. Asserts what the bench's table
rests on, never a speed: every engine gives a finite positive rate on every scene, and on the
robot scene every engine holds the KUKA iiwa's pose (final joint error under
scenes.ROBOT_MAX_ERROR): the engines compared do the same job. Needs ../shared/realdata for the
KUKA's URDF (skipped, naming the folder, where it is absent).

A peer named in requirements.lock that does not import is an error, not a skip (the project's
venv installs the lock: scripts/setup_venv.sh); a peer outside the lock is skipped.
"""

import json
import math
import os
import subprocess
import sys
import warnings

import pytest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
BENCH = os.path.join(ROOT, "bench", "peers", "peers_bench.py")
sys.path.insert(0, os.path.join(ROOT, "bench", "peers"))

import scenes  # noqa: E402

PEERS = {"sapien": "sapien", "pybullet": "pybullet", "mujoco": "mujoco"}  # engine: module


def _locked(module):
    with open(os.path.join(ROOT, "requirements.lock"), encoding="utf-8") as f:
        lock = f.read()
    # the MuJoCo bindings come with mujoco-core
    names = {"mujoco": ("mujoco-core", "mujoco")}.get(module, (module,))
    return any(f"\n{n}==" in lock for n in names)


def _engines():
    engines = ["partsim"]
    for engine, module in PEERS.items():
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # SAPIEN: "Failed to find system libvulkan"
                __import__(module)
        except ImportError as e:
            if _locked(module):
                raise ImportError(f"{module} is in requirements.lock but does not import ({e}): "
                                  "run scripts/setup_venv.sh") from e
            continue
        engines.append(engine)
    return engines


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    if not os.path.isfile(scenes.KUKA_URDF):
        pytest.skip(f"the KUKA iiwa's URDF is not there ({scenes.KUKA_URDF}): "
                    "../shared/realdata is absent")
    engines = _engines()
    out = tmp_path_factory.mktemp("peers") / "peers.json"
    proc = subprocess.run(
        [sys.executable, BENCH, "--reps", "1", "--steps", "20", "--engines", ",".join(engines),
         "--json", str(out)],
        capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    with open(out, encoding="utf-8") as f:
        return engines, json.load(f), proc.stdout


def test_every_installed_engine_runs_every_scene(bench):
    engines, data, table = bench
    assert data["skipped"] == {}
    for scene in scenes.SCENES:
        assert sorted(data["results"][scene]) == sorted(engines), scene
        for engine, r in data["results"][scene].items():
            assert math.isfinite(r["median"]) and r["median"] > 0, (scene, engine, r)
            assert r["steps"] == 20
        assert data["results"][scene]["partsim"]["ratio"] == pytest.approx(1.0)
    # the table names every engine on each scene's rows
    for engine in engines:
        assert sum(line.split()[1:2] == [engine] for line in table.splitlines()) == 3, table


def test_every_engine_holds_the_robot_pose(bench):
    engines, data, _ = bench
    for engine in engines:
        r = data["results"]["robot"][engine]
        assert len(r["q"]) == len(scenes.ROBOT_POSE), engine
        assert 0 <= r["error"] < scenes.ROBOT_MAX_ERROR, (engine, r["error"], r["q"])


def test_every_engine_moves_the_drawers_toward_the_target(bench):
    # 20 steps (0.04 s) from closed: every drawer has moved out, none past the target
    engines, data, _ = bench
    for engine in engines:
        q = data["results"]["drawer"][engine]["q"]
        assert len(q) == 3 and all(0.005 < x < scenes.DRAWER_TARGET for x in q), (engine, q)
