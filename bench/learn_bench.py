"""Throughput of SAC training on the door and drawer tasks (python/partsim/learn).

Measures, on one thread for torch (as ``partsim learn train`` runs):

* one SAC gradient update (batch 256, two 256-unit hidden layers: both critics, the actor, the
  entropy coefficient and the target networks) for the raw (46), mobility (25) and visual
  (RGB-D and mask at 128 x 96 plus the 14-number robot state) observations;
* one ``act`` call for a batch of 4 observations (the policy's forward pass, sampling);
* the whole training loop (``Trainer``, drawer task, mobility observations, 4 environments in
  one ``VectorOpenCabinetEnv``, a shared buffer) at 0, 0.25 and 1 updates per environment step,
  in environment steps/s and updates/s, after its warm-up.

Each measurement is repeated ``--repeats`` times, the configurations taking turns; the table
shows medians and the minimum-maximum over the repeats. From the loop's rate at the default
0.25 updates per step it projects the wall time of one 1M-step run and of the paper's 24 runs
(3 representations x 2 tasks x 4 training sizes) on this machine, one run per core.

Usage: PARTSIM_PYTHON_DIR=build/python /usr/bin/python3 bench/learn_bench.py [--repeats R]
       [--loop-steps N]
"""

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(
    0, os.path.abspath(os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python")))
)

import torch  # noqa: E402
from gymnasium.spaces import Box, Dict  # noqa: E402

import partsim  # noqa: E402
import partsim.envs as envs  # noqa: E402
from partsim.learn import SAC, ReplayBuffer, TrainConfig, Trainer  # noqa: E402


def spaces(obs):
    """The observation space of an environment with ``obs`` observations (no scene made)."""
    state = Box(-np.inf, np.inf, (envs.ROBOT_STATE_SIZE,), np.float32)
    if obs == "raw":
        return Box(-np.inf, np.inf, (2 * envs.RAW_MAX_DOF + envs.ROBOT_STATE_SIZE,), np.float32)
    if obs == "mobility":
        return Box(-np.inf, np.inf, (11 + envs.ROBOT_STATE_SIZE,), np.float32)
    h, w = 96, 128
    return Dict({"rgb": Box(0, 255, (h, w, 3), np.uint8),
                 "depth": Box(0.0, np.inf, (h, w), np.float32),
                 "mask": Box(0, 1, (h, w), np.uint8), "state": state})


def filled_buffer(space, n=2048, seed=0):
    rng = np.random.default_rng(seed)
    buffer = ReplayBuffer(n, space, 7, seed=seed)

    def sample(k):
        if isinstance(space, Dict):
            return {"rgb": rng.integers(0, 255, (k, 96, 128, 3), dtype=np.uint8),
                    "depth": rng.uniform(0.5, 3, (k, 96, 128)).astype(np.float32),
                    "mask": rng.integers(0, 2, (k, 96, 128), dtype=np.uint8),
                    "state": rng.normal(size=(k, 14)).astype(np.float32)}
        return rng.normal(size=(k,) + space.shape).astype(np.float32)

    for _ in range(n // 64):
        buffer.add(sample(64), rng.uniform(-1, 1, (64, 7)).astype(np.float32),
                   rng.normal(size=64), sample(64), np.zeros(64, bool))
    return buffer, sample


def time_updates(obs, count):
    space = spaces(obs)
    agent = SAC(space, 7, seed=0)
    buffer, sample = filled_buffer(space)
    agent.update(buffer.sample(256))  # warm-up
    t = time.perf_counter()
    for _ in range(count):
        agent.update(buffer.sample(256))
    update_ms = (time.perf_counter() - t) / count * 1e3
    batch = sample(4)
    agent.act(batch)
    t = time.perf_counter()
    for _ in range(count * 4):
        agent.act(batch)
    act_ms = (time.perf_counter() - t) / (count * 4) * 1e3
    return update_ms, act_ms


def time_loop(updates_per_step, steps):
    ps = partsim._partsim
    objects = ps.find_task_objects(ps.parse_task_type("drawer"), 4, 0)
    env = envs.VectorOpenCabinetEnv(4, task="drawer", obs_mode="mobility", objects=objects,
                                    max_episode_steps=250)
    try:
        agent = SAC(env.single_observation_space, env.single_action_space, seed=0)
        buffer = ReplayBuffer(100_000, env.single_observation_space, 7, seed=0)
        with tempfile.TemporaryDirectory() as out:
            # the warm-up (random actions, no updates) is one run; the measured one resumes it
            warm = TrainConfig(total_steps=1000, warmup_steps=1000, checkpoint_interval=0,
                               log_interval=10**9, quiet=True, updates_per_step=updates_per_step)
            Trainer(env, agent, buffer, out, warm).train()
            cfg = TrainConfig(total_steps=1000 + steps, warmup_steps=1000, checkpoint_interval=0,
                              log_interval=10**9, quiet=True, updates_per_step=updates_per_step)
            summary = Trainer(env, agent, buffer, out, cfg, resume=True).train()
    finally:
        env.close()
    return summary["env_steps_per_s"], summary["updates_per_s"]


def fmt(values, digits=1):
    med = statistics.median(values)
    return f"{med:.{digits}f} ({min(values):.{digits}f}-{max(values):.{digits}f})"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--updates", type=int, default=50, help="timed updates per repeat")
    parser.add_argument("--loop-steps", type=int, default=4000,
                        help="timed environment steps of the loop per repeat")
    args = parser.parse_args()
    torch.set_num_threads(1)
    print(f"machine: {platform.machine()}, {os.cpu_count()} hardware threads; torch "
          f"{torch.__version__}, {torch.get_num_threads()} thread")
    updates = {o: [] for o in ("raw", "mobility", "visual")}
    acts = {o: [] for o in updates}
    loops = {u: [] for u in (0.0, 0.25, 1.0)}
    for r in range(args.repeats):
        for obs in updates:
            u, a = time_updates(obs, args.updates if obs != "visual" else max(5, args.updates // 5))
            updates[obs].append(u)
            acts[obs].append(a)
        for upd in loops:
            loops[upd].append(time_loop(upd, args.loop_steps))
        print(f"repeat {r + 1}/{args.repeats} done", file=sys.stderr)
    print("\n| observation | update, ms (batch 256) | act, ms (batch 4) |\n|---|---:|---:|")
    for obs in updates:
        print(f"| {obs} | {fmt(updates[obs])} | {fmt(acts[obs], 2)} |")
    print("\n| updates per env step | env steps/s | updates/s |\n|---:|---:|---:|")
    for upd, runs in loops.items():
        print(f"| {upd:g} | {fmt([s for s, _ in runs], 0)} | {fmt([u for _, u in runs], 0)} |")
    rate = statistics.median(s for s, _ in loops[0.25])
    run_h = 1e6 / rate / 3600
    print(f"\nprojection at 0.25 updates per step: one 1M-step run {run_h:.1f} h; the paper's 24 "
          f"runs {24 * run_h:.0f} h of one core, {24 * run_h / max(1, os.cpu_count()):.0f} h "
          f"on this machine's {os.cpu_count()} cores (state observations; visual runs are "
          "slower, see the update time)")


if __name__ == "__main__":
    main()
