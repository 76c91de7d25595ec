"""partsim beside the engines users would pick instead: SAPIEN 3 (PhysX on the CPU), PyBullet and
MuJoCo's Python bindings, on the same scenes (scenes.py): the drawer task's cabinet with PD-driven
drawers, a pile of free boxes, and the KUKA iiwa holding a pose. Physics steps only, no
rendering, one step per Python call, every engine at partsim's default step.

Each measurement (one scene in one engine) runs in a process of its own (run_one.py): the
engines load native libraries of their own (PhysX and its threads, Bullet, two builds of
MuJoCo), and a fresh process keeps one engine's allocations, caches and threads out of the
next one's numbers. Within each repetition the engines take turns, the order rotated by one
place from one repetition to the next; the table shows each median over the repetitions of the
steps per second of the wall clock, its minimum-maximum, the ratio of the median to partsim's,
process CPU ms per step and, for the robot, each engine's final joint error max |q - q*| (rad).
A peer that is not installed is skipped with the reason.

Usage:
  PARTSIM_PYTHON_DIR=build/python .venv/bin/python bench/peers/peers_bench.py \\
      [--reps 5] [--steps N] [--scenes drawer,boxes,robot] \\
      [--engines partsim,sapien,pybullet,mujoco] [--sleep] [--json OUT]
"""

import argparse
import importlib.util
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
REPO = os.path.dirname(os.path.dirname(HERE))
PYTHON_DIR = os.path.abspath(
    os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python")))
sys.path.insert(0, PYTHON_DIR)

import scenes  # noqa: E402

ENGINES = ("partsim", "sapien", "pybullet", "mujoco")
MODULES = {"partsim": "partsim", "sapien": "sapien", "pybullet": "pybullet", "mujoco": "mujoco"}


def missing(engine):
    """Why an engine cannot run here, or None."""
    if importlib.util.find_spec(MODULES[engine]) is None:
        return f"the Python module '{MODULES[engine]}' is not installed"
    return None


def measure(engine, scene, steps, assets, dt, sleep):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [PYTHON_DIR] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    proc = subprocess.run(
        [sys.executable, "-W", "ignore", os.path.join(HERE, "run_one.py"), engine, scene,
         str(steps), assets, repr(dt), "1" if sleep else "0"],
        capture_output=True, text=True, env=env)
    for line in proc.stdout.splitlines():
        if "PEERS_RESULT " in line:
            return json.loads(line.split("PEERS_RESULT ", 1)[1])
    raise RuntimeError(f"{engine} on {scene} failed (exit {proc.returncode}):\n"
                       f"{proc.stdout[-2000:]}{proc.stderr[-2000:]}")


def run(args):
    """{scene: {engine: summary}}, {engine: reason skipped}, the asset facts."""
    engines = [e for e in args.engines if e in ENGINES]
    skipped = {e: missing(e) for e in engines if missing(e)}
    engines = [e for e in engines if e not in skipped]
    if "partsim" not in engines:
        raise SystemExit("peers_bench: partsim must run (it is the reference of the ratios)")
    dt = scenes.default_timestep()
    with tempfile.TemporaryDirectory(prefix="partsim-peers-") as assets:
        info = scenes.prepare_assets(assets)
        samples = {s: {e: [] for e in engines} for s in args.scenes}
        for rep in range(args.reps):
            order = engines[rep % len(engines):] + engines[:rep % len(engines)]
            for scene in args.scenes:
                steps = args.steps or scenes.DEFAULT_STEPS[scene]
                for engine in order:
                    r = measure(engine, scene, steps, assets, dt, args.sleep)
                    samples[scene][engine].append(r)
                    print(f"  rep {rep + 1}/{args.reps} {scene:6s} {engine:8s} "
                          f"{r['rate']:10.1f} steps/s", file=sys.stderr, flush=True)
    results = {}
    for scene, by_engine in samples.items():
        ref = statistics.median(r["rate"] for r in by_engine["partsim"])
        results[scene] = {}
        for engine, rs in by_engine.items():
            rates = [r["rate"] for r in rs]
            med = statistics.median(rates)
            last = rs[-1]
            results[scene][engine] = {
                "version": last["version"], "steps": last["steps"], "median": med,
                "min": min(rates), "max": max(rates), "ratio": med / ref,
                "cpu_ms": statistics.median(r["cpu_ms"] for r in rs),
                "error": last.get("error"), "q": last.get("q"), "mean_z": last.get("mean_z"),
            }
    return results, skipped, dict(info, dt=dt)


def print_table(results, skipped, info, args):
    print(f"peers bench: {args.reps} repetitions, dt = {info['dt']} s (partsim's default), "
          f"sleeping {'on where the engine has it' if args.sleep else 'off'}; "
          f"{platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}")
    print(f"drawer: StorageFurniture object {info['cabinet_object_index']} (seed 0), "
          f"{info['cabinet_joints']} drawers, {info['cabinet_boxes']} boxes and "
          f"{info['cabinet_meshes']} convex meshes")
    for engine, why in skipped.items():
        print(f"skipped {engine}: {why}")
    print(f"{'scene':7s} {'engine':9s} {'steps':>6s} {'steps/s':>10s} {'min-max':>19s} "
          f"{'ratio':>6s} {'CPU ms':>7s}  result")
    for scene, by_engine in results.items():
        for engine, r in by_engine.items():
            if r["error"] is not None:
                extra = f"joint error {r['error']:.5f} rad"
            elif r["mean_z"] is not None:
                extra = f"mean box height {r['mean_z']:.4f} m"
            else:
                extra = "drawers " + " ".join(f"{q:.4f}" for q in r["q"]) + " m"
            print(f"{scene:7s} {engine:9s} {r['steps']:6d} {r['median']:10.1f} "
                  f"{r['min']:9.1f}-{r['max']:<9.1f} {r['ratio']:6.3f} {r['cpu_ms']:7.4f}  "
                  f"{extra}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--reps", type=int, default=5, help="repetitions (median reported)")
    ap.add_argument("--steps", type=int, default=0,
                    help="timed steps per measurement (default: per scene, "
                    + ", ".join(f"{k} {v}" for k, v in scenes.DEFAULT_STEPS.items()) + ")")
    ap.add_argument("--scenes", default=",".join(scenes.SCENES))
    ap.add_argument("--engines", default=",".join(ENGINES))
    ap.add_argument("--sleep", action="store_true",
                    help="leave sleeping on in the engines that have it (SAPIEN, PyBullet)")
    ap.add_argument("--json", help="also write the results to this file")
    args = ap.parse_args()
    args.scenes = [s for s in args.scenes.split(",") if s]
    args.engines = [e for e in args.engines.split(",") if e]
    for s in args.scenes:
        if s not in scenes.SCENES:
            ap.error(f"--scenes: unknown scene '{s}' (known: {', '.join(scenes.SCENES)})")
    for e in args.engines:
        if e not in ENGINES:
            ap.error(f"--engines: unknown engine '{e}' (known: {', '.join(ENGINES)})")
    results, skipped, info = run(args)
    print_table(results, skipped, info, args)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump({"info": info, "skipped": skipped, "results": results,
                       "reps": args.reps, "sleep": args.sleep}, f, indent=1)


if __name__ == "__main__":
    main()
