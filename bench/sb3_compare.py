#!/usr/bin/env python3
"""partsim's SAC beside Stable-Baselines3's on the same task, objects and hyper-parameters: does
the learner or the task keep the drawer from being learned?

Both learners train on the run's training objects (partsim.learn.protocol's split: the same
objects for both) with the paper's SAC settings as partsim's `learn train` uses them: 4
environments filling one replay buffer, 2,000 warm-up steps of random actions, one update per
4 environment steps (SB3: train_freq 1 over 4 environments, gradient_steps 1), batches of 256,
Adam at 3e-4, gamma 0.99, tau 0.005, two 256-unit layers, the entropy coefficient tuned from
0.1 towards minus the action size. Then both play the protocol's evaluation (deterministic
episodes, the same seeds) on the training and the unseen objects.

  partsim  `partsim learn train` into OUT/partsim, `partsim learn evaluate` (eval.json)
  sb3      stable_baselines3.SAC on partsim.envs.OpenCabinetEnv copies (SB3's DummyVecEnv),
           its Monitor logs in OUT/sb3, the model OUT/sb3/model.zip, OUT/sb3/eval.json

Prints the paper's metric for both (door: final angle, degrees; drawer: success at 80% of the
range) and the mean training return over the run's last 10% of episodes; OUT/compare.json
holds it all, OUT/curves.png the two training curves. The two learners can run side by side: `--only partsim` and `--only sb3` in two
processes, then `--only report`.

Usage: PYTHONPATH=build/python .venv/bin/python bench/sb3_compare.py --task drawer
       --obs mobility --train-objects 4 --steps 100000 --seed 0 --out runs/compare [--episodes 20]
"""

import argparse
import csv
import json
import os
import subprocess
import sys
import time

import numpy as np

from partsim import _cli, envs
from partsim.learn import protocol


def train_sb3(a, config, train_objects, out):
    import torch
    from stable_baselines3 import SAC
    from stable_baselines3.common.monitor import Monitor
    from stable_baselines3.common.vec_env import DummyVecEnv

    torch.set_num_threads(1)
    os.makedirs(out, exist_ok=True)

    def make(i):
        def thunk():
            env = envs.OpenCabinetEnv(**protocol.env_kwargs(config, train_objects))
            return Monitor(env, os.path.join(out, f"monitor_{i}"), info_keywords=("success",))
        return thunk

    vec = DummyVecEnv([make(i) for i in range(config.num_envs)])
    vec.seed(a.seed)
    model = SAC("MlpPolicy", vec, learning_rate=config.lr, buffer_size=config.buffer_size or
                1_000_000, learning_starts=config.warmup_steps, batch_size=config.batch_size,
                tau=0.005, gamma=0.99, train_freq=1, gradient_steps=1,
                ent_coef=f"auto_{config.init_alpha}",
                policy_kwargs={"net_arch": list(config.hidden_sizes)}, seed=a.seed,
                device="cpu")
    start = time.monotonic()
    model.learn(a.steps)
    seconds = time.monotonic() - start
    model.save(os.path.join(out, "model.zip"))
    vec.close()
    return model, seconds


def evaluate_sb3(a, model, doc, out):
    """The protocol's evaluation (the same environments and seeds as `learn evaluate`) with
    SB3's deterministic policy; writes out/eval.json in its layout."""
    from partsim.learn.trainer import evaluate as run_episodes

    config = protocol.RunConfig.from_json(doc["config"])
    result = {"episodes": a.episodes, "seed": 1000, "policy": "sb3", "task": config.task,
              "obs": config.obs, "train_objects": config.train_objects, "steps": a.steps}
    for name in ("train", "test"):
        opened, progress = [], []
        for k, obj in enumerate(doc[name]):
            env = protocol._make_env(config, [obj], min(a.episodes, config.num_envs))
            try:
                ev = run_episodes(env, None, a.episodes, seed=1000 + 1000 * k,
                                  policy=lambda o: model.predict(o, deterministic=True)[0])
            finally:
                env.close()
            opened += [i["opened"] for i in ev.infos]
            progress += [i["progress"] for i in ev.infos]
        result[name] = {"metric": protocol._score(config.task, np.array(opened),
                                                  np.array(progress))}
    with open(os.path.join(out, "eval.json"), "w", encoding="utf-8") as f:
        json.dump(result, f, indent=1)
    return result


def late_return(rows):
    """Mean return of the last 10% of the episodes (rows of (step, return))."""
    if not rows:
        return float("nan")
    rows = sorted(rows)
    tail = rows[-max(1, len(rows) // 10):]
    return float(np.mean([r for _, r in tail]))


def sb3_returns(out):
    rows = []
    for name in sorted(os.listdir(out)):
        if name.startswith("monitor_") and name.endswith(".monitor.csv"):
            with open(os.path.join(out, name), encoding="utf-8") as f:
                lines = [line for line in f if not line.startswith("#")]
            for r in csv.DictReader(lines):
                rows.append((float(r["t"]), float(r["r"])))
    return rows


def sb3_curve(out, every=2000):
    """SB3's training episodes binned by environment steps: (steps, mean return, success)."""
    eps = []
    for name in sorted(os.listdir(out)):
        if name.startswith("monitor_") and name.endswith(".monitor.csv"):
            with open(os.path.join(out, name), encoding="utf-8") as f:
                lines = [line for line in f if not line.startswith("#")]
            eps += [(float(r["t"]), float(r["r"]), r["success"] == "True", int(r["l"]))
                    for r in csv.DictReader(lines)]
    eps.sort()  # by wall time: the four environments' episodes interleaved
    curve, steps, chunk = [], 0, []
    for _, ret, ok, length in eps:
        steps += length
        chunk.append((ret, ok))
        if steps >= (len(curve) + 1) * every:
            curve.append((steps, np.mean([c[0] for c in chunk]), np.mean([c[1] for c in chunk])))
            chunk = []
    return curve


def plot(a, run, out, path):
    """The two learners' training curves, return and success rate, in one PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(os.path.join(run, "progress.csv"), encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r.get("mean_return") not in (None, "", "nan")]
    ours = [(float(r["env_steps"]), float(r["mean_return"]), float(r["success_rate"]))
            for r in rows]
    theirs = sb3_curve(out)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.5))
    for k, label in ((1, "mean episode return"), (2, "success rate (90% of the range)")):
        for name, curve in (("partsim SAC", ours), ("SB3 SAC", theirs)):
            axes[k - 1].plot([c[0] for c in curve], [c[k] for c in curve], label=name)
        axes[k - 1].set_xlabel("environment steps")
        axes[k - 1].set_title(label)
    axes[0].legend()
    fig.suptitle(f"{a.task}, {a.obs}, {a.train_objects} training objects, seed {a.seed}")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    return path


def partsim_returns(run):
    with open(os.path.join(run, "progress.csv"), encoding="utf-8") as f:
        return [(float(r["env_steps"]), float(r["mean_return"])) for r in csv.DictReader(f)
                if r.get("mean_return") not in (None, "", "nan")]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="drawer", choices=("door", "drawer"))
    ap.add_argument("--obs", default="mobility", choices=("raw", "mobility"))
    ap.add_argument("--train-objects", type=int, default=4)
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--out", required=True)
    ap.add_argument("--only", choices=("partsim", "sb3", "report"))
    ap.add_argument("--gripper", default="closed", choices=("closed", "free"))
    a = ap.parse_args()
    config = protocol.RunConfig(task=a.task, obs=a.obs, train_objects=a.train_objects,
                                steps=a.steps, seed=a.seed, gripper=a.gripper)
    train_objects, test_objects = protocol.task_objects(config)
    doc = {"config": config.to_json(), "train": train_objects, "test": test_objects}
    os.makedirs(a.out, exist_ok=True)
    run = os.path.join(a.out, "partsim")
    cli = _cli.find_cli()
    if a.only in (None, "partsim"):
        start = time.monotonic()
        subprocess.run([cli, "learn", "train", "--task", a.task, "--obs", a.obs,
                        "--train-objects", str(a.train_objects), "--steps", str(a.steps),
                        "--seed", str(a.seed), "--gripper", a.gripper, "--out", run,
                        "--quiet"], check=True)
        with open(os.path.join(a.out, "partsim_seconds.json"), "w", encoding="utf-8") as f:
            json.dump({"seconds": time.monotonic() - start}, f)
        subprocess.run([cli, "learn", "evaluate", run, "--episodes", str(a.episodes),
                        "--quiet"], check=True)
    if a.only in (None, "sb3"):
        model, seconds = train_sb3(a, config, train_objects, os.path.join(a.out, "sb3"))
        with open(os.path.join(a.out, "sb3_seconds.json"), "w", encoding="utf-8") as f:
            json.dump({"seconds": seconds}, f)
        evaluate_sb3(a, model, doc, os.path.join(a.out, "sb3"))
    if a.only in (None, "report"):
        report = {}
        for name, folder, returns in (
                ("partsim SAC", run, lambda: partsim_returns(run)),
                ("SB3 SAC", os.path.join(a.out, "sb3"),
                 lambda: sb3_returns(os.path.join(a.out, "sb3")))):
            with open(os.path.join(folder, "eval.json"), encoding="utf-8") as f:
                ev = json.load(f)
            secs_file = os.path.join(a.out, ("partsim" if "partsim" in name else "sb3")
                                     + "_seconds.json")
            with open(secs_file, encoding="utf-8") as f:
                secs = json.load(f)["seconds"]
            report[name] = {"train": ev["train"]["metric"], "test": ev["test"]["metric"],
                            "late_training_return": late_return(returns()),
                            "steps_per_s": a.steps / secs}
        with open(os.path.join(a.out, "compare.json"), "w", encoding="utf-8") as f:
            json.dump(report, f, indent=1)
        try:
            print("curves:", plot(a, run, os.path.join(a.out, "sb3"),
                                  os.path.join(a.out, "curves.png")))
        except ImportError:  # matplotlib is optional: the CSVs hold the curves
            pass
        metric = "final angle (deg)" if a.task == "door" else "success at 80%"
        print(f"{a.task}, {a.obs}, {a.train_objects} objects, {a.steps:,} steps, seed {a.seed}")
        print(f"| learner | train, {metric} | test | late training return | env steps/s |")
        print("|---|---:|---:|---:|---:|")
        for name, r in report.items():
            print(f"| {name} | {r['train']:.3g} | {r['test']:.3g} | "
                  f"{r['late_training_return']:.2f} | {r['steps_per_s']:.0f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
