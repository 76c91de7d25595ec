"""Steps per second of the Gymnasium environments (python/partsim/envs.py).

Measures, on the drawer task with the gripper starting on the handle:

* the physics alone: ``scene.step(20)`` (one control period) on a task's scene, the
  gripper's drives holding their last targets (no task layer: no controller, gravity
  compensation or reward);
* the bare ``ArticulationTask`` loop (``apply_action`` + ``step``, no observation): the
  reference;
* ``OpenCabinetEnv.step`` with mobility, raw and visual observations (visual: the front camera
  at 128 x 96, rasterizer backend);
* ``VectorOpenCabinetEnv`` with 1, 2 and 4 environments (mobility), counted in environment
  steps (``num_envs`` per call);
* ``step_tasks`` (the vector environment's parallel step, in C++ without the GIL) on 1, 2 and 4
  tasks, no observation: the C++ side of the vector rows, so that the difference is the share
  of Python per environment step.

``--vector`` measures only the bare task, the vector environments and ``step_tasks`` (no single
environments, no visual). Every run also prints the speed-ups from 1 to 2 and 4 copies (the
median of each repeat's ratio, and the fastest repeat's rate over the fastest repeat's: on a
shared machine, the repeats that the neighbours disturbed least), and the Python share of the
vector environment's step; ``--samples FILE`` writes every repeat's numbers as JSON.

Each measurement runs ``--steps`` environment steps (``--visual-steps`` for visual; after an
untimed warm-up step, with random actions in [-0.3, 0.3], reset whenever an episode ends) and
is repeated ``--repeats`` times, the configurations taking turns within each repeat. The table
shows the median steps/s of the wall clock and its minimum-maximum over the repeats, the ratio
of each median to the bare task's, and the process CPU time per environment step (all threads
summed; less sensitive to other jobs on a shared machine).

Usage: PARTSIM_PYTHON_DIR=build/python python3 bench/env_bench.py [--steps N] [--repeats R]
       [--vector] [--samples FILE]
"""

import argparse
import json
import os
import platform
import statistics
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(
    0, os.path.abspath(os.environ.get("PARTSIM_PYTHON_DIR", os.path.join(REPO, "build", "python")))
)

import partsim  # noqa: E402
import partsim.envs as envs  # noqa: E402

EPISODE = 100  # max_episode_steps of the environments
# every configuration steps the same cabinet: the first generated one with a drawer
OBJECT = partsim.find_task_objects(partsim.TaskType.PULL_DRAWER, 1, 0)[0]


class Bare:
    """ArticulationTask.apply_action + step with the environment's action scaling; no
    observation, reward or info."""

    name = "bare ArticulationTask.step()"
    num_envs = 1

    def __init__(self):
        self.env = envs.OpenCabinetEnv(objects=OBJECT, max_episode_steps=EPISODE)
        self.env.reset(seed=0)
        self.task = self.env.task
        self.scale = np.array([envs.MAX_LINEAR_SPEED] * 3 + [envs.MAX_ANGULAR_SPEED] * 3 + [1.0])
        self.k = 0

    def step(self, a):
        self.task.apply_action(a.astype(np.float64) * self.scale)
        self.task.step()
        self.k += 1
        if self.k % EPISODE == 0:
            self.task.reset(self.k)

    def close(self):
        self.env.close()


class Physics:
    """scene.step(20) per environment step on the task's scene: what the physics costs without
    the task layer (the gripper's drives keep their targets; gravity is not compensated)."""

    name = "physics only: scene.step(20)"
    num_envs = 1

    def __init__(self):
        self.env = envs.OpenCabinetEnv(objects=OBJECT, max_episode_steps=EPISODE)
        self.env.reset(seed=0)
        self.scene = self.env.task.scene
        rate = self.env.task.options.control_rate
        self.substeps = round(1.0 / (rate * self.scene.get_timestep()))
        self.k = 0

    def step(self, a):
        self.scene.step(self.substeps)
        self.k += 1
        if self.k % EPISODE == 0:
            self.env.task.reset(self.k)

    def close(self):
        self.env.close()


class Single:
    def __init__(self, obs_mode):
        self.name = f"OpenCabinetEnv, {obs_mode}" + (" 128x96" if obs_mode == "visual" else "")
        self.num_envs = 1
        self.env = envs.OpenCabinetEnv(
            obs_mode=obs_mode, objects=OBJECT, max_episode_steps=EPISODE, camera_size=(128, 96)
        )
        self.env.reset(seed=0)

    def step(self, a):
        _, _, terminated, truncated, _ = self.env.step(a)
        if terminated or truncated:
            self.env.reset()

    def close(self):
        self.env.close()


class Vector:
    def __init__(self, n):
        self.name = f"VectorOpenCabinetEnv x{n}, mobility"
        self.num_envs = n
        self.env = envs.VectorOpenCabinetEnv(
            n, obs_mode="mobility", objects=OBJECT, max_episode_steps=EPISODE
        )
        self.env.reset(seed=0)

    def step(self, a):
        self.env.step(a)  # next-step autoreset restarts finished episodes

    def close(self):
        self.env.close()


class StepTasks:
    """partsim._partsim.step_tasks on ``n`` tasks per call (the actions scaled as the vector
    environment scales them), no observation, reward or info: what the vector environment's
    step costs in C++."""

    def __init__(self, n):
        self.name = f"step_tasks x{n} (C++ only)"
        self.num_envs = n
        self.envs = [
            envs.OpenCabinetEnv(objects=OBJECT, max_episode_steps=EPISODE) for _ in range(n)
        ]
        for e in self.envs:
            e.reset(seed=0)
        self.tasks = [e.task for e in self.envs]
        self.k = 0

    def step(self, a):
        partsim._partsim.step_tasks(self.tasks, envs._task_action(a.astype(np.float64)))
        self.k += 1
        if self.k % EPISODE == 0:
            for t in self.tasks:
                t.reset(self.k)

    def close(self):
        for e in self.envs:
            e.close()


def measure(runner, steps, seed):
    """(environment steps per second of wall time, process CPU ms per environment step)."""
    calls = max(1, steps // runner.num_envs)
    batched = isinstance(runner, (Vector, StepTasks))
    shape = (calls + 1, runner.num_envs, 7) if batched else (calls + 1, 7)
    acts = np.random.default_rng(seed).uniform(-0.3, 0.3, shape).astype(np.float32)
    runner.step(acts[0])  # untimed
    t, c = time.perf_counter(), time.process_time()
    for k in range(calls):
        runner.step(acts[k + 1])
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    n = calls * runner.num_envs
    return n / wall, 1000.0 * cpu / n


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=200, help="environment steps per measurement")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--visual-steps", type=int, default=100, help="steps of the visual runs")
    ap.add_argument("--samples", help="also write every repeat's (steps/s, CPU ms) as JSON here")
    ap.add_argument(
        "--vector",
        action="store_true",
        help="only the bare task, the vector environments and step_tasks, with speed-ups",
    )
    args = ap.parse_args()

    print(
        f"partsim {partsim.__version__}, python {platform.python_version()}, numpy "
        f"{np.__version__}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}"
    )
    t0 = time.perf_counter()
    if args.vector:
        runners = [Bare()]
    else:
        runners = [Bare(), Physics(), Single("mobility"), Single("raw"), Single("visual")]
    runners += [Vector(n) for n in (1, 2, 4)]
    runners += [StepTasks(n) for n in (1, 2, 4)]
    print(f"built {len(runners)} configurations in {time.perf_counter() - t0:.0f} s", flush=True)
    # the configurations take turns within each repeat, so that changes of the machine's load
    # spread over all of them
    samples = {r.name: [] for r in runners}
    for rep in range(args.repeats):
        for r in runners:
            steps = args.visual_steps if "visual" in r.name else args.steps
            samples[r.name].append(measure(r, steps, rep))
        print(f"  repeat {rep + 1}/{args.repeats} done", flush=True)
    for r in runners:
        r.close()
    if args.samples:
        with open(args.samples, "w") as f:
            json.dump(samples, f)

    print(
        f"\nload average at the end {os.getloadavg()[0]:.2f}; "
        f"{time.perf_counter() - t0:.0f} s in all; {args.repeats} repeats; "
        f"control rate 25 Hz, physics 500 Hz (20 substeps per env step)\n"
    )
    bare = statistics.median(x[0] for x in samples[runners[0].name])
    print(
        "| configuration | env steps/s (median) | min-max | median / bare task "
        "| CPU ms per env step (median) |"
    )
    print("|---|---:|---:|---:|---:|")
    for r in runners:
        rate = [x[0] for x in samples[r.name]]
        cpu = [x[1] for x in samples[r.name]]
        med = statistics.median(rate)
        print(
            f"| {r.name} | {med:.0f} | {min(rate):.0f}-{max(rate):.0f} | {med / bare:.2f} "
            f"| {statistics.median(cpu):.2f} |"
        )

    # speed-ups from 1 copy to n, per repeat (the copies ran one after the other, so each
    # repeat's ratio cancels some of the machine's drift), then their median; and the share of
    # Python: the vector environment's wall time per environment step minus step_tasks'
    print(
        "\n| speed-up | median of the repeats' ratios | min-max "
        "| fastest repeat / fastest repeat |"
    )
    print("|---|---:|---:|---:|")
    for kind, name in (("VectorOpenCabinetEnv", "VectorOpenCabinetEnv x{}, mobility"),
                       ("step_tasks", "step_tasks x{} (C++ only)")):
        for n in (2, 4):
            one, many = samples[name.format(1)], samples[name.format(n)]
            ratios = [b[0] / a[0] for a, b in zip(one, many)]
            best = max(x[0] for x in many) / max(x[0] for x in one)
            print(
                f"| {kind} 1 -> {n} copies | {statistics.median(ratios):.2f} "
                f"| {min(ratios):.2f}-{max(ratios):.2f} | {best:.2f} |"
            )
    for n in (1, 2, 4):
        vec = samples[f"VectorOpenCabinetEnv x{n}, mobility"]
        cpp = samples[f"step_tasks x{n} (C++ only)"]
        vec = statistics.median(1000.0 / x[0] for x in vec)
        cpp = statistics.median(1000.0 / x[0] for x in cpp)
        print(
            f"x{n}: wall ms per env step: vector env {vec:.3f}, step_tasks {cpp:.3f}, "
            f"Python's share {vec - cpp:.3f} ({100 * (vec - cpp) / vec:.0f}%)"
        )


if __name__ == "__main__":
    main()
