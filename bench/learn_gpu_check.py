#!/usr/bin/env python3
"""SAC's update on a GPU: the learning protocol's check of a GPU machine.

Times SAC updates (batch 256; both critics, the actor, the entropy coefficient and the target
networks) for the raw, mobility and visual observations (RGB-D and the target mask at 128 x 96
plus the 14-number robot state, the CNN of the visual agent) on --device, and the `act` call
of a batch of 4, from a replay buffer of random transitions; then a short stretch of visual
training updates (--train-updates) with its losses, to check that they stay finite and change.
It needs only PyTorch and NumPy: partsim.learn's `sac` and `replay` modules are loaded from this
tree without the partsim package (whose C++ extension is built for the build VM's Python), so
the environment steps of a real visual run are not part of it.

The defaults should take a few minutes on a data-centre GPU (not yet run on one); on the build
VM's 2 cores, --device cpu --updates 3 --train-updates 3 takes 30 s (a visual update there is
about 3 s). Where the GPU machine's Python lacks Gymnasium, copy its wheels along
(bench/README.md, "SAC's update on a GPU").

Usage: python3 bench/learn_gpu_check.py [--device auto|cpu|cuda] [--updates 200]
       [--train-updates 2000] [--out FILE.json]
"""

import argparse
import importlib.util
import json
import os
import platform
import statistics
import sys
import time

import numpy as np
import torch

LEARN = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python",
                     "partsim", "learn")


def load(name):
    spec = importlib.util.spec_from_file_location(f"partsim_learn_{name}",
                                                  os.path.join(LEARN, f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


sac = load("sac")
replay = load("replay")

from gymnasium.spaces import Box, Dict  # noqa: E402


def space(obs):
    state = Box(-np.inf, np.inf, (14,), np.float32)
    if obs == "raw":
        return Box(-np.inf, np.inf, (46,), np.float32)
    if obs == "mobility":
        return Box(-np.inf, np.inf, (25,), np.float32)
    return Dict({"rgb": Box(0, 255, (96, 128, 3), np.uint8),
                 "depth": Box(0.0, np.inf, (96, 128), np.float32),
                 "mask": Box(0, 1, (96, 128), np.uint8), "state": state})


def sample(sp, k, rng):
    if isinstance(sp, Dict):
        return {"rgb": rng.integers(0, 255, (k, 96, 128, 3), dtype=np.uint8),
                "depth": rng.uniform(0.5, 3, (k, 96, 128)).astype(np.float32),
                "mask": rng.integers(0, 2, (k, 96, 128), dtype=np.uint8),
                "state": rng.normal(size=(k, 14)).astype(np.float32)}
    return rng.normal(size=(k,) + sp.shape).astype(np.float32)


def buffer_of(sp, n=2048, seed=0):
    rng = np.random.default_rng(seed)
    buf = replay.ReplayBuffer(n, sp, 7, seed=seed)
    for _ in range(n // 64):
        buf.add(sample(sp, 64, rng), rng.uniform(-1, 1, (64, 7)).astype(np.float32),
                rng.normal(size=64), sample(sp, 64, rng), np.zeros(64, bool))
    return buf


def sync(device):
    if device.type == "cuda":
        torch.cuda.synchronize()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", default="auto")
    ap.add_argument("--updates", type=int, default=200)
    ap.add_argument("--train-updates", type=int, default=2000)
    ap.add_argument("--out")
    a = ap.parse_args()
    name = "cuda" if a.device == "auto" and torch.cuda.is_available() else \
        ("cpu" if a.device == "auto" else a.device)
    device = torch.device(name)
    machine = torch.cuda.get_device_name(device) if device.type == "cuda" else \
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores"
    result = {"device": name, "machine": machine, "torch": torch.__version__, "obs": {}}
    print(f"SAC updates on {name} ({machine}), torch {torch.__version__}")
    print("| observation | update, batch 256 (ms) | updates/s | act, batch 4 (ms) |")
    print("|---|---:|---:|---:|")
    for obs in ("raw", "mobility", "visual"):
        sp = space(obs)
        agent = sac.SAC(sp, 7, seed=0, device=name)
        buf = buffer_of(sp)
        agent.update(buf.sample(256))  # warm-up (cuDNN's choice of kernels, allocations)
        sync(device)
        times = []
        for _ in range(a.updates):
            batch = buf.sample(256)
            t = time.perf_counter()
            agent.update(batch)
            sync(device)
            times.append(time.perf_counter() - t)
        update_ms = statistics.median(times) * 1e3
        obs4 = sample(sp, 4, np.random.default_rng(1))
        t = time.perf_counter()
        for _ in range(a.updates):
            agent.act(obs4)
        act_ms = (time.perf_counter() - t) / a.updates * 1e3
        result["obs"][obs] = {"update_ms": update_ms, "updates_per_s": 1e3 / update_ms,
                              "act_ms": act_ms}
        print(f"| {obs} | {update_ms:.2f} | {1e3 / update_ms:.0f} | {act_ms:.2f} |")
    # a stretch of visual training updates: losses finite and moving
    sp = space("visual")
    agent = sac.SAC(sp, 7, seed=0, device=name)
    buf = buffer_of(sp, 4096, seed=2)
    start = time.perf_counter()
    first = last = None
    for i in range(a.train_updates):
        info = agent.update(buf.sample(256))
        if first is None:
            first = info
        last = info
    sync(device)
    seconds = time.perf_counter() - start
    finite = all(np.isfinite(float(v)) for v in last.values())
    result["visual_training"] = {"updates": a.train_updates, "seconds": seconds,
                                 "first": {k: float(v) for k, v in first.items()},
                                 "last": {k: float(v) for k, v in last.items()},
                                 "finite": finite}
    print(f"visual training: {a.train_updates} updates in {seconds:.1f} s "
          f"({a.train_updates / seconds:.0f}/s); losses finite: {finite}; q1 loss "
          f"{float(first['q1_loss']):.3g} -> {float(last['q1_loss']):.3g}")
    if a.out:
        with open(a.out, "w", encoding="utf-8") as f:
            json.dump(result, f, indent=1)
    return 0 if finite else 1


if __name__ == "__main__":
    sys.exit(main())
