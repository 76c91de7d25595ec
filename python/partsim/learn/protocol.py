"""The SAPIEN paper's learning experiment on partsim's tasks (its Table 3): Soft Actor-Critic
trained on 2, 4, 8 or 16 doors or drawers and tested on unseen ones.

A run is a folder. :func:`train` writes ``run.json`` (the whole configuration: task, state
representation, the training and test objects, the agent's and the loop's options),
``progress.csv`` and checkpoints (see :mod:`partsim.learn.trainer`) and ``curves.png``;
:func:`evaluate` writes ``eval.json`` and ``eval.csv``; :func:`table` reads runs and lays out
Table 3 beside the paper's numbers. The command line is ``partsim learn`` (or
``python3 -m partsim.learn``): ``train``, ``evaluate``, ``table`` and ``curves``.

Objects. The pool is every object with a target for the task (a ``drawer`` or a
``rotation_door`` with a handle and a finite range): the generated StorageFurniture objects
(the first ``16 + test_objects`` of the generator's dataset seed) or, with ``dataset``, the
PartNet-Mobility folders under that root. The pool is shuffled once by ``split_seed`` (not by
the training seed, so runs of every seed and size share one test set). Training on N objects
takes the first N of that order, so the 2 objects are among the 4, the 4 among the 8 and so
on; the test objects are the ones after the first 16 (``test_objects`` of them, or all the
rest), never trained on at any size.

Metrics, as the paper's: for doors, the door's final opening in degrees, averaged over
episodes; for drawers, the fraction of episodes that end with the drawer open to at least 80%
of its range. Evaluation episodes are deterministic (the tanh of the policy's mean) and seeded.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import os
import sys
import time

import numpy as np

from .._device import resolve_device  # noqa: F401 (part of this module's API)
from .._files import atomic_write

__all__ = [
    "PAPER_STEPS",
    "PAPER_TABLE3",
    "TRAIN_SIZES",
    "RunConfig",
    "task_objects",
    "env_kwargs",
    "train",
    "evaluate_run",
    "merge_evaluations",
    "table",
    "plot_curves",
    "main",
]

TRAIN_SIZES = (2, 4, 8, 16)
# the environment steps of each of the paper's runs
PAPER_STEPS = 1_000_000
# Table 3 of the SAPIEN paper: door (final angle, degrees) and drawer (success rate at 80% of
# the range) after 1M steps, for 2 / 4 / 8 / 16 training objects
PAPER_TABLE3 = {
    ("raw", "door", "train"): (85.4, 70.5, 50.5, 38.4),
    ("raw", "door", "test"): (14.7, 18.7, 21.2, 27.3),
    ("raw", "drawer", "train"): (0.84, 0.82, 0.77, 0.75),
    ("raw", "drawer", "test"): (0.61, 0.63, 0.66, 0.66),
    ("mobility", "door", "train"): (88.7, 78.6, 59.2, 41.1),
    ("mobility", "door", "test"): (22.9, 27.3, 27.5, 32.8),
    ("mobility", "drawer", "train"): (0.83, 0.81, 0.79, 0.78),
    ("mobility", "drawer", "test"): (0.65, 0.65, 0.69, 0.68),
    ("visual", "door", "train"): (90.2, 65.2, 56.7, 32.1),
    ("visual", "door", "test"): (21.7, 24.5, 28.1, 29.6),
    ("visual", "drawer", "train"): (0.80, 0.72, 0.69, 0.63),
    ("visual", "drawer", "test"): (0.59, 0.60, 0.61, 0.60),
}
DRAWER_SUCCESS = 0.8  # the paper's drawer metric: open to 80% of the range
RUN_FILE = "run.json"
EVAL_FILE = "eval.json"


@dataclasses.dataclass
class RunConfig:
    """Everything that defines a run (written to ``run.json``).

    ``task``: "door" or "drawer"; ``obs``: "raw", "mobility" or "visual"; ``train_objects``: N;
    ``steps``: environment steps; ``seed``: of the agent, the buffer and the episodes;
    ``dataset``: a PartNet-Mobility root, or None for generated objects (``dataset_seed``);
    ``split_seed``, ``test_objects``: the object split (see the module's docstring; 0 test
    objects: all after the first 16); ``num_envs``: environments stepped together, sharing one
    replay buffer; ``max_episode_steps``; ``warmup_steps``, ``updates_per_step``,
    ``buffer_size`` (0: a million transitions for states, 20,000 for pictures, whose
    transitions are large), ``batch_size``, ``hidden_sizes``, ``lr``, ``init_alpha`` (the
    entropy coefficient's start, tuned from there); ``checkpoint_interval``,
    ``log_interval``: in environment steps. ``gripper``: "closed" (the action is the hand's
    6-value twist; the fingers stay closed on the handle the episode starts on) or "free" (a
    7th action commands the fingers; runs written before this option existed are "free").
    """

    task: str = "drawer"
    obs: str = "mobility"
    train_objects: int = 4
    steps: int = 100_000
    seed: int = 0
    dataset: str | None = None
    dataset_seed: int = 0
    split_seed: int = 0
    test_objects: int = 8
    num_envs: int = 4
    max_episode_steps: int = 250
    warmup_steps: int = 2_000
    updates_per_step: float = 0.25
    buffer_size: int = 0  # 0: 1,000,000 transitions for states, 20,000 for pictures
    batch_size: int = 256
    hidden_sizes: tuple = (256, 256)
    lr: float = 3e-4
    init_alpha: float = 0.1
    checkpoint_interval: int = 10_000
    log_interval: int = 2_000
    gripper: str = "closed"

    def check(self):
        """Raises ValueError naming the first option out of range."""
        if self.task not in ("door", "drawer"):
            raise ValueError(f"task must be 'door' or 'drawer', got {self.task!r}")
        if self.obs not in ("raw", "mobility", "visual"):
            raise ValueError(f"obs must be 'raw', 'mobility' or 'visual', got {self.obs!r}")
        if self.gripper not in ("closed", "free"):
            raise ValueError(f"gripper must be 'closed' or 'free', got {self.gripper!r}")
        for name in ("train_objects", "num_envs", "max_episode_steps", "batch_size",
                     "log_interval"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")
        for name in ("steps", "warmup_steps", "test_objects", "checkpoint_interval",
                     "buffer_size"):
            if int(getattr(self, name)) < 0:
                raise ValueError(f"{name} must not be negative, got {getattr(self, name)}")
        if not (self.updates_per_step >= 0 and math.isfinite(self.updates_per_step)):
            raise ValueError(f"updates_per_step must be >= 0, got {self.updates_per_step}")
        for name in ("lr", "init_alpha"):
            v = float(getattr(self, name))
            if not (v > 0 and math.isfinite(v)):
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")

    def to_json(self) -> dict:
        """The configuration as JSON values."""
        d = dataclasses.asdict(self)
        d["hidden_sizes"] = list(self.hidden_sizes)
        return d

    @classmethod
    def from_json(cls, d: dict) -> "RunConfig":
        """A configuration from ``to_json``'s dict; unknown keys raise ValueError."""
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - known)
        if unknown:
            raise ValueError(f"unknown run options {unknown}")
        d = dict(d)
        d.setdefault("gripper", "free")  # written before the option: the fingers were free
        if "hidden_sizes" in d:
            try:
                d["hidden_sizes"] = tuple(int(h) for h in d["hidden_sizes"])
            except (TypeError, ValueError, OverflowError):  # 1e999 reads as inf
                raise ValueError(f"hidden_sizes must be a list of integers, got "
                                 f"{str(d['hidden_sizes'])[:80]}") from None
        return cls(**d)


# --- objects -------------------------------------------------------------------------------


def _ps():
    from .. import _partsim

    return _partsim


def _dataset_pool(task: str, root: str) -> list:
    """The PartNet-Mobility folders under ``root`` (sorted by path) with a target for the task;
    folders that cannot be read are left out with a warning on stderr."""
    ps = _ps()
    if not os.path.isdir(root):
        raise ValueError(f"dataset: {root!r} is not a folder")
    loader = ps.PartNetMobilityLoader()
    urdf = loader.urdf
    urdf.load_collisions = False  # only the labels and joints are read here
    loader.urdf = urdf
    kind = ps.parse_task_type(task)
    pool = []
    for entry in ps.parse_partnet_mobility_batch(root, loader):
        if not entry.ok:
            print(f"partsim learn: skipping {entry.folder}: {entry.error}", file=sys.stderr)
            continue
        if ps.find_task_targets(entry.object, kind):
            pool.append(entry.folder)
    return pool


def task_objects(config: RunConfig) -> tuple:
    """(training objects, test objects) of a run: generated StorageFurniture indices (ints) or
    PartNet-Mobility folders (str), split as the module's docstring says. Raises ValueError
    when the pool is too small for the training objects and at least one test object."""
    largest = max(TRAIN_SIZES[-1], config.train_objects)
    if config.dataset is None:
        count = largest + (config.test_objects or 8)
        pool = list(_ps().find_task_objects(_ps().parse_task_type(config.task), count,
                                            config.dataset_seed))
    else:
        pool = _dataset_pool(config.task, config.dataset)
    order = np.random.default_rng(np.random.SeedSequence([config.split_seed, 7])).permutation(
        len(pool))
    pool = [pool[int(i)] for i in order]
    # with a small pool the test objects are what the largest training set leaves
    held = min(largest, len(pool) - 1)
    if config.train_objects > held:
        raise ValueError(
            f"train_objects = {config.train_objects}: the pool has {len(pool)} objects with a "
            f"{config.task}, and at least one must stay unseen for the test")
    rest = pool[held:]
    test = rest[: config.test_objects] if config.test_objects else rest
    return pool[: config.train_objects], test


def env_kwargs(config: RunConfig, objects) -> dict:
    """The keyword arguments of the run's environments (``OpenCabinetEnv``, and every copy of
    ``VectorOpenCabinetEnv``) on ``objects``."""
    return dict(task=config.task, obs_mode=config.obs, objects=list(objects),
                dataset_seed=config.dataset_seed, max_episode_steps=config.max_episode_steps,
                gripper_action=config.gripper == "free")


def _make_env(config: RunConfig, objects, num_envs: int):
    from .. import envs

    return envs.VectorOpenCabinetEnv(num_envs, **env_kwargs(config, objects))


# --- training ------------------------------------------------------------------------------


def _read_run(run: str) -> dict:
    path = os.path.join(run, RUN_FILE)
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
    except FileNotFoundError:
        raise ValueError(f"{run!r} is not a run folder (no {RUN_FILE})") from None
    except (OSError, ValueError, RecursionError) as e:  # RecursionError: nested too deep
        raise ValueError(f"{path}: cannot be read: {e}") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("config"), dict):
        raise ValueError(f"{path}: has no 'config' object")
    return doc


def _make_agent(config: RunConfig, env, device: str = "cpu"):
    """A fresh SAC agent for the run's options and the environment's spaces, on ``device``."""
    from .sac import SAC, SACConfig

    sac = SACConfig(hidden_sizes=tuple(config.hidden_sizes), lr=config.lr,
                    batch_size=config.batch_size, init_alpha=config.init_alpha)
    return SAC(env.single_observation_space, env.single_action_space, sac, seed=config.seed,
               device=device)




def _make_buffer(config: RunConfig, env, action_dim: int):
    """The run's replay buffer (training only: evaluation needs none)."""
    from .replay import ReplayBuffer

    capacity = config.buffer_size or (20_000 if config.obs == "visual" else 1_000_000)
    return ReplayBuffer(capacity, env.single_observation_space, action_dim, seed=config.seed)


def train(config: RunConfig, out: str, quiet: bool = False, device: str = "auto") -> dict:
    """Trains SAC on the run's training objects into the folder ``out`` and returns a summary
    (steps, seconds, environment steps/s, updates/s).

    A folder holding a run of the same configuration continues from its last checkpoint: a run
    cut short by a crash loses nothing, and one started again with more ``steps`` goes on to
    them (equal to a run of that length from the start when the steps done are a multiple of
    ``checkpoint_interval``). A run that has trained ``steps`` already (the environments step
    together, so a run may end up to ``num_envs - 1`` steps past them) is finished: it returns
    at once, changing nothing, with ``already_finished`` True in the summary. A folder holding a
    different run, or one that has trained more steps than ``steps`` and than its own
    configuration asks, is refused with a ValueError. Torch runs on one thread per process
    unless ``torch.set_num_threads`` was called before. ``device`` (see
    :func:`resolve_device`) is where the agent's networks and updates run; it is not part of
    the run, which may continue on another device.
    """
    import torch

    from .trainer import TrainConfig, Trainer

    config.check()
    device = resolve_device(device)
    out = os.fspath(out)
    train_objs, test_objs = task_objects(config)
    doc = {"config": config.to_json(), "train": train_objs, "test": test_objs}
    run_file = os.path.join(out, RUN_FILE)
    resume = os.path.exists(run_file)
    if resume:
        old = _read_run(out)
        # the same run, perhaps with more steps: it continues from its last checkpoint (the
        # old options read as RunConfig reads them, so that an option added since has the
        # value the run trained with)
        try:
            old_config = RunConfig.from_json(old["config"]).to_json()
        except (TypeError, ValueError):  # not options this code wrote
            old_config = old["config"]
        differ = sorted(k for k in set(old_config) | set(doc["config"])
                        if k != "steps" and old_config.get(k) != doc["config"].get(k))
        if differ:
            raise ValueError(f"{out!r} holds a run with other options ({', '.join(differ)}); "
                             "choose another folder")
        if old["train"] != train_objs or old["test"] != test_objs:
            raise ValueError(f"{out!r}: the objects of the run changed (the dataset under "
                             f"{config.dataset!r} is not what it was)")
        done = _checkpoint_steps(out)
        if config.steps < done and config.steps < int(old["config"].get("steps", 0)):
            raise ValueError(f"{out!r} has trained {done} steps already, more than --steps "
                             f"{config.steps}")
        if done >= config.steps:
            return {"env_steps": done, "already_finished": True}
    if not resume or doc != old:
        os.makedirs(out, exist_ok=True)
        _write_atomic(run_file, json.dumps(doc, indent=1))

    if torch.get_num_threads() > 1 and "OMP_NUM_THREADS" not in os.environ:
        torch.set_num_threads(1)
    env = _make_env(config, train_objs, config.num_envs)
    try:
        agent = _make_agent(config, env, device)
        buffer = _make_buffer(config, env, agent.action_dim)
        loop = TrainConfig(total_steps=config.steps, warmup_steps=config.warmup_steps,
                           updates_per_step=config.updates_per_step,
                           checkpoint_interval=config.checkpoint_interval,
                           log_interval=config.log_interval, seed=config.seed, quiet=quiet)
        start = time.monotonic()
        summary = Trainer(env, agent, buffer, out, loop, resume=resume).train()
        seconds = time.monotonic() - start
    finally:
        env.close()
    try:
        if summary and summary.get("env_steps", 0) > 0:  # a run of 0 steps has no rows
            plot_curves(out)
    except ImportError:  # matplotlib is optional: the CSV has the curves
        pass
    summary = dict(summary or {})
    summary.setdefault("seconds", seconds)
    summary["device"] = device
    return summary


def _checkpoint_steps(run: str) -> int:
    """Environment steps of a run's last checkpoint (0 without one). Raises ValueError naming
    checkpoint.json when it cannot be read or its env_steps is not a count."""
    from .trainer import POINTER

    path = os.path.join(run, POINTER)
    try:
        with open(path, encoding="utf-8") as f:
            steps = json.load(f)["env_steps"]
    except FileNotFoundError:
        return 0
    except (OSError, ValueError, KeyError, TypeError, RecursionError) as e:
        raise ValueError(f"{path}: cannot be read: {e}") from None
    if not (isinstance(steps, int) and not isinstance(steps, bool) and 0 <= steps < 10**15):
        raise ValueError(f"{path}: env_steps must be a count of steps, got {steps!r}")
    return steps


def _load_agent(run: str, config: RunConfig, env):
    """The agent of a run's last checkpoint."""
    import torch

    from .trainer import POINTER

    agent = _make_agent(config, env)
    pointer = os.path.join(run, POINTER)
    try:
        with open(pointer, encoding="utf-8") as f:
            folder = json.load(f)["dir"]
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise ValueError(f"{run!r} has no checkpoint to evaluate ({pointer}: {e})") from None
    state = torch.load(os.path.join(run, folder, "agent.pt"), map_location="cpu")
    agent.load_state_dict(state)
    return agent


def _trained_steps(run: str, config: RunConfig) -> int:
    """The environment steps of the checkpoint an evaluation plays (checkpoint.json), or the
    run's --steps when there is none or it cannot be read (a random baseline of a run never
    trained)."""
    try:
        return _checkpoint_steps(run) or int(config.steps)
    except ValueError:
        return int(config.steps)


# --- evaluation ----------------------------------------------------------------------------


def _score(task: str, opened: np.ndarray, progress: np.ndarray) -> float:
    """The paper's metric over episodes: mean final door angle (degrees), or the drawer success
    rate at 80% of the range."""
    if task == "door":
        return float(np.degrees(np.mean(opened)))
    return float(np.mean(progress >= DRAWER_SUCCESS))


def _parse_shard(shard) -> tuple:
    """(i, N) from "i/N" or a pair; ValueError unless 0 <= i < N."""
    try:
        i, n = (int(x) for x in (shard.split("/") if isinstance(shard, str) else shard))
    except (ValueError, TypeError):
        raise ValueError(f"--shard wants i/N with 0 <= i < N (e.g. 0/4), got {shard!r}") from None
    if not 0 <= i < n:
        raise ValueError(f"--shard wants i/N with 0 <= i < N (e.g. 0/4), got '{i}/{n}'")
    return i, n


def _evaluate_objects(run: str, doc: dict, episodes: int, seed: int, which, policy: str,
                      shard, quiet: bool) -> list:
    """Plays the episodes of the objects of ``which`` (training, then test objects, in the run's
    order) whose index in that order is i modulo N for ``shard`` = (i, N); returns one record
    per object: its set, its index in the set, its name and its episodes as [return, length,
    opened, progress, success] rows. An object's episodes depend on nothing but the run, the
    seed and the object's place, so any shard plays them as one run does."""
    from .trainer import evaluate as run_episodes

    config = RunConfig.from_json(doc["config"])
    agent = None
    records, index = [], 0
    for s, name in enumerate(which):
        for k, obj in enumerate(doc[name]):
            index += 1
            if (index - 1) % shard[1] != shard[0]:
                continue
            env = _make_env(config, [obj], min(episodes, config.num_envs))
            try:
                if agent is None and policy == "agent":
                    agent = _load_agent(run, config, env)
                random_policy = None
                if policy == "random":
                    rng = np.random.default_rng([seed, s, k])  # the object's own stream
                    size = env.single_action_space.shape[0]
                    random_policy = lambda o: rng.uniform(  # noqa: E731
                        -1, 1, (len(_first(o)), size))
                ev = run_episodes(env, agent, episodes, seed=seed + 1000 * k,
                                  policy=random_policy)
            finally:
                env.close()
            rows = [[float(ev.returns[j]), int(ev.lengths[j]), float(ev.infos[j]["opened"]),
                     float(ev.infos[j]["progress"]), bool(ev.infos[j]["success"])]
                    for j in range(len(ev.returns))]
            records.append({"set": name, "index": k, "object": obj, "episodes": rows})
            if not quiet:
                opened = np.array([r[2] for r in rows])
                progress = np.array([r[3] for r in rows])
                print(f"{name} object {obj}: {_score(config.task, opened, progress):.3f}",
                      file=sys.stderr)
    return records


def _write_evaluation(run: str, doc: dict, episodes: int, seed: int, which, policy: str,
                      records: list) -> dict:
    """eval.json (or eval_random.json) and its CSV from every object's record, as one run of
    :func:`evaluate_run` writes them; returns the summary."""
    config = RunConfig.from_json(doc["config"])
    result = {"episodes": int(episodes), "seed": int(seed), "policy": policy,
              "task": config.task, "obs": config.obs, "train_objects": config.train_objects,
              "steps": _trained_steps(run, config), "run_steps": config.steps,
              "metric": "final angle (degrees)" if config.task == "door"
              else f"success rate at {int(DRAWER_SUCCESS * 100)}% of the range"}
    by_place = {(r["set"], r["index"]): r for r in records}
    rows = []
    for name in which:
        per_object, episodes_all = [], []
        for k in range(len(doc[name])):
            eps = by_place[(name, k)]["episodes"]
            opened = np.array([e[2] for e in eps], dtype=float)
            progress = np.array([e[3] for e in eps], dtype=float)
            per_object.append({"object": doc[name][k],
                               "metric": _score(config.task, opened, progress),
                               "mean_return": float(np.mean([e[0] for e in eps]))})
            rows += [[name, doc[name][k], j] + list(e) for j, e in enumerate(eps)]
            episodes_all += eps
        result[name] = {
            "metric": _score(config.task, np.array([e[2] for e in episodes_all], dtype=float),
                             np.array([e[3] for e in episodes_all], dtype=float)),
            "mean_return": float(np.mean([e[0] for e in episodes_all])),
            "success_rate": float(np.mean([bool(e[4]) for e in episodes_all])),
            "objects": per_object,
        }
    stem = "eval" if policy == "agent" else "eval_random"
    _write_atomic(os.path.join(run, stem + ".json"), json.dumps(result, indent=1))
    lines = [["set", "object", "episode", "return", "length", "opened", "progress", "success"]]
    text = _csv_text(lines + rows)
    _write_atomic(os.path.join(run, stem + ".csv"), text)
    return result


def _csv_text(rows) -> str:
    import io

    buf = io.StringIO(newline="")
    csv.writer(buf).writerows(rows)
    return buf.getvalue()


def _write_atomic(path: str, text: str) -> None:
    """Writes ``text`` (UTF-8) whole or not at all (partsim._files.atomic_write)."""
    atomic_write(path, lambda f: f.write(text.encode("utf-8")))


def evaluate_run(run: str, episodes: int = 20, seed: int = 1000, which=("train", "test"),
                 policy: str = "agent", quiet: bool = False, shard=None,
                 results: str | None = None) -> dict:
    """Evaluates a run's last checkpoint: ``episodes`` deterministic episodes on each training
    and each test object (``which``), seeds ``seed``, ``seed + 1``, ... per object. Writes
    ``eval.json`` (with ``policy="agent"``) and ``eval.csv`` (one row per episode) into the
    run and returns the summary: per set, the paper's metric, the mean return and success rate
    (the task's own, 90% of the range) and the per-object metric.

    ``policy="random"`` plays uniform random actions instead (a baseline; written to
    ``eval_random.json`` / ``.csv``), each object's from its own seeded stream.

    ``shard="i/N"`` plays only the objects whose index (training objects first, then test
    objects) is i modulo N and writes their episodes to ``results`` (a JSON file; nothing is
    written into the run); :func:`merge_evaluations` makes the N shards' files into the files
    one run writes, byte for byte. Returns the shard's file's content then.
    """
    if episodes < 1:
        raise ValueError(f"episodes must be at least 1, got {episodes}")
    if policy not in ("agent", "random"):
        raise ValueError(f"policy must be 'agent' or 'random', got {policy!r}")
    part = (0, 1) if shard is None else _parse_shard(shard)
    if shard is not None and not results:
        raise ValueError("--shard needs --results FILE (the shard's episodes)")
    doc = _read_run(run)
    which = tuple(which)
    records = _evaluate_objects(run, doc, episodes, seed, which, policy, part, quiet)
    if shard is None and not results:
        return _write_evaluation(run, doc, episodes, seed, which, policy, records)
    out = {"kind": "partsim learn evaluate shard", "run_config": doc["config"],
           "episodes": int(episodes), "seed": int(seed), "policy": policy,
           "which": list(which), "shard": list(part), "objects": records}
    _write_atomic(results, json.dumps(out, indent=1))
    if shard is None:
        return _write_evaluation(run, doc, episodes, seed, which, policy, records)
    return out


def merge_evaluations(run: str, files) -> dict:
    """Writes the run's eval.json and eval.csv (eval_random.* for a random policy) from the
    shards' results files of :func:`evaluate_run`, the same bytes as one unsharded run; every
    object must be in exactly one file, and the files must be of this run and of one
    evaluation (episodes, seed, policy, sets). Returns the summary."""
    files = list(files)
    if not files:
        raise ValueError("--merge needs the shards' results files")
    doc = _read_run(run)
    first, records, seen = None, [], {}
    for path in files:
        try:
            with open(path, encoding="utf-8") as f:
                part = json.load(f)
        except (OSError, ValueError, RecursionError) as e:  # RecursionError: nested too deep
            raise ValueError(f"{path}: cannot be read: {e}") from None
        if not isinstance(part, dict) or part.get("kind") != "partsim learn evaluate shard":
            raise ValueError(f"{path}: not a results file of 'partsim learn evaluate --shard'")
        if part.get("run_config") != doc["config"]:
            raise ValueError(f"{path}: evaluates another run than {run!r}")
        if not (isinstance(part.get("which"), list) and
                all(w in ("train", "test") for w in part["which"])):
            raise ValueError(f"{path}: its 'which' is not a list of train and test")
        key = {k: part.get(k) for k in ("episodes", "seed", "policy", "which")}
        if first is None:
            first = (path, key)
        elif key != first[1]:
            differ = ", ".join(k for k in key if key[k] != first[1][k])
            raise ValueError(f"{path} and {first[0]} are of different evaluations ({differ})")
        objects = part.get("objects")
        if not isinstance(objects, list):
            raise ValueError(f"{path}: its 'objects' is not a list")
        for r in objects:
            if not (isinstance(r, dict) and r.get("set") in key["which"] and
                    type(r.get("index")) is int and 0 <= r["index"] < len(doc[r["set"]]) and
                    isinstance(r.get("episodes"), list)):
                what = {k: r.get(k) for k in ("set", "index")} if isinstance(r, dict) else r
                raise ValueError(f"{path}: holds an object this run does not have, or one "
                                 f"without its episodes ({str(what)[:80]})")
            place = (r["set"], r["index"])
            if place in seen:
                raise ValueError(f"{path} and {seen[place]} both hold {r['set']} object "
                                 f"{r['index']} ({r['object']}): overlapping shards")
            seen[place] = path
            records.append(r)
    which = first[1]["which"]
    missing = [f"{name} object {k} ({obj})" for name in which
               for k, obj in enumerate(doc[name]) if (name, k) not in seen]
    if missing:
        raise ValueError(f"the files lack {len(missing)} object(s): {', '.join(missing[:5])}"
                         + (" ..." if len(missing) > 5 else "") + " (a shard missing?)")
    return _write_evaluation(run, doc, first[1]["episodes"], first[1]["seed"], which,
                             first[1]["policy"], records)


def _first(obs):
    return next(iter(obs.values())) if isinstance(obs, dict) else obs


# --- the table -----------------------------------------------------------------------------


def table(runs, fmt: str = "markdown") -> str:
    """Table 3's layout from evaluated runs: rows (state, train|test), columns door and drawer
    at 2 / 4 / 8 / 16 training objects; each cell "ours (paper)", ours the mean over the runs
    (seeds) of that cell and "-" where no run is. A cell with a run of fewer steps than the
    paper's 1,000,000 is marked "†" (reduced). ``fmt``: "markdown" or "csv" (one row per cell
    with both values, the number of runs and the fewest steps of its runs)."""
    cells, steps, cell_steps = {}, set(), {}
    for run in runs:
        path = os.path.join(run, EVAL_FILE)
        try:
            with open(path, encoding="utf-8") as f:
                ev = json.load(f)
        except FileNotFoundError:
            raise ValueError(f"{run!r} has not been evaluated (no {EVAL_FILE}; run "
                             "'partsim learn evaluate' first)") from None
        except (OSError, ValueError) as e:
            raise ValueError(f"{path}: cannot be read: {e}") from None
        steps.add(int(ev.get("steps", 0)))
        for part in ("train", "test"):
            if part in ev:
                key = (ev["obs"], ev["task"], part, int(ev["train_objects"]))
                cells.setdefault(key, []).append(float(ev[part]["metric"]))
                cell_steps[key] = min(cell_steps.get(key, PAPER_STEPS), int(ev.get("steps", 0)))
    if fmt == "csv":
        lines = ["obs,task,set,train_objects,ours,runs,paper,steps"]
        for (obs, task, part, n), vals in sorted(cells.items()):
            paper = PAPER_TABLE3.get((obs, task, part))
            ref = paper[TRAIN_SIZES.index(n)] if paper and n in TRAIN_SIZES else ""
            lines.append(f"{obs},{task},{part},{n},{np.mean(vals):.4g},{len(vals)},{ref},"
                         f"{cell_steps[(obs, task, part, n)]}")
        return "\n".join(lines) + "\n"
    if fmt != "markdown":
        raise ValueError(f"fmt must be 'markdown' or 'csv', got {fmt!r}")
    head = ["state", "set"] + [f"door {n}" for n in TRAIN_SIZES] + \
        [f"drawer {n}" for n in TRAIN_SIZES]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * 2 + "---:|" * 8]
    for obs in ("raw", "mobility", "visual"):
        for part in ("train", "test"):
            row = [f"{obs}-exp", part]
            for task in ("door", "drawer"):
                paper = PAPER_TABLE3[(obs, task, part)]
                for i, n in enumerate(TRAIN_SIZES):
                    vals = cells.get((obs, task, part, n))
                    ref = f"{paper[i]:.1f}" if task == "door" else f"{paper[i]:.2f}"
                    ours = "-" if not vals else (f"{np.mean(vals):.1f}" if task == "door"
                                                 else f"{np.mean(vals):.2f}")
                    if vals and cell_steps[(obs, task, part, n)] < PAPER_STEPS:
                        ours += "†"
                    row.append(f"{ours} ({ref})")
            lines.append("| " + " | ".join(row) + " |")
    other = sorted(k for k in cells if k[3] not in TRAIN_SIZES)
    for obs, task, part, n in other:
        lines.append(f"\n{obs}-exp {task} {part} on {n} objects: "
                     f"{np.mean(cells[(obs, task, part, n)]):.3g}")
    lines.append("\ncells: ours, mean over runs (the paper's Table 3 in brackets); door: final "
                 "angle in degrees, drawer: success rate at 80% of the range; training steps "
                 "per run: " + ", ".join(f"{n:,}" for n in sorted(steps)) + " (the paper: "
                 f"{PAPER_STEPS:,}); †: reduced, a run of the cell has fewer steps than the "
                 "paper's")
    return "\n".join(lines) + "\n"


# --- curves --------------------------------------------------------------------------------


def plot_curves(run, out: str | None = None, labels=None) -> str:
    """Draws learning curves from progress.csv (mean episode return, success rate, critic and
    policy losses, entropy coefficient against environment steps) into a PNG and returns its
    path. Needs matplotlib.

    ``run``: one run folder (``out`` defaults to RUN/curves.png), or a list of them, drawn over
    each other in the same panels (seeds of one setting, or settings side by side; ``out`` is
    then required), each named in the legend by ``labels`` or its folder's name."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = [run] if isinstance(run, (str, os.PathLike)) else list(run)
    if not runs:
        raise ValueError("curves needs at least one RUN folder")
    if len(runs) > 1 and not out:
        raise ValueError("curves of several runs need --out FILE.png")
    labels = list(labels) if labels else [os.path.basename(os.path.normpath(r)) for r in runs]
    if len(labels) != len(runs):
        raise ValueError(f"{len(labels)} labels for {len(runs)} runs")
    tables, configs = [], []
    for r in runs:
        path = os.path.join(r, "progress.csv")
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        if not rows:
            raise ValueError(f"{path} has no rows yet")
        tables.append(rows)
        configs.append(_read_run(r)["config"])

    def col(rows, name):
        return np.array([float(r[name]) if r.get(name) not in (None, "") else np.nan
                         for r in rows])

    def describe(c, seed=True):
        text = f"{c['task']}, {c['obs']}-exp, {c['train_objects']} objects"
        return text + (f", seed {c['seed']}" if seed else "")

    if len(runs) == 1:
        title = describe(configs[0])
    elif len({describe(c, seed=False) for c in configs}) == 1:
        title = describe(configs[0], seed=False) + f", {len(runs)} runs"
    else:
        title = f"{len(runs)} runs"
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    panels = [("mean_return", "mean episode return"), ("success_rate", "success rate (90%)"),
              ("q1_loss", "loss"), ("alpha", "entropy coefficient")]
    for ax, (name, label) in zip(axes.flat, panels):
        for k, rows in enumerate(tables):
            steps = col(rows, "env_steps")
            line, = ax.plot(steps, col(rows, name), marker="." if len(runs) == 1 else None,
                            lw=1, label=labels[k] if len(runs) > 1 else None)
            if name == "q1_loss":
                ax.plot(steps, col(rows, "policy_loss"), lw=1, ls="--", color=line.get_color(),
                        label="policy" if len(runs) == 1 else None)
        ax.set_xlabel("environment steps")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if name == "q1_loss":
            ax.set_ylabel("loss: critic (Q1) solid, policy dashed")
        if len(runs) > 1 and name == "success_rate":
            ax.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    out = out or os.path.join(runs[0], "curves.png")
    fig.savefig(out, dpi=80)
    plt.close(fig)
    return out


# --- command line --------------------------------------------------------------------------

USAGE = """usage:
  partsim learn train --task door|drawer --obs raw|mobility|visual --train-objects N
                      --steps S --seed K --out RUN [--dataset ROOT] [options]
  partsim learn evaluate RUN [--episodes 20] [--seed E] [--random] [--quiet]
                         [--shard i/N --results FILE | --merge FILE...]
  partsim learn sweep --out SWEEP [--tasks door,drawer] [--obs raw,mobility,visual]
                      [--train-objects 2,4,8,16] [--seeds 0,1,2] --steps S [train options]
                      [--episodes E] [--ray auto|ADDRESS]
  partsim learn table RUN... [--csv]
  partsim learn curves RUN... [--out FILE.png] [--labels A,B,...]

train      trains SAC on N training objects (generated StorageFurniture, or the PartNet-Mobility
           folders under ROOT) into the folder RUN: run.json, progress.csv (returns, success,
           losses, steps/s), checkpoints, curves.png. Run it again with the same options to
           continue after a crash (a finished run is left as it is and exits 0), or with a
           larger --steps to train it further.
evaluate   plays the run's policy deterministically, --episodes per object, on its training
           and its unseen test objects; writes RUN/eval.json and RUN/eval.csv and prints the
           paper's metric (door: final angle, degrees; drawer: success at 80% of the range).
           --random plays uniform random actions instead (eval_random.json), a baseline.
           --shard i/N plays only the objects whose index (training ones first) is i mod N
           and writes their episodes to --results FILE; --merge FILE... writes eval.json and
           eval.csv from all shards' files, the bytes of one run (docs/distributed.md).
sweep      the paper's grid (task x state x training objects x seed) as training runs
           SWEEP/<task>-<state>-n<N>-s<seed>, each resumable, then evaluates them and prints
           Table 3; with --ray, the runs are tasks on a Ray cluster (SWEEP on a path every node
           sees). Run it again to continue: finished runs and evaluations are skipped.
table      prints the SAPIEN paper's Table 3 layout from evaluated runs (means over seeds),
           each cell beside the paper's number.
curves     draws RUN/progress.csv into a PNG (default RUN/curves.png); several runs are
           drawn over each other (seeds, settings side by side) into --out.

train options (defaults in brackets):
  --num-envs E [4]            environments stepped together, one shared replay buffer
  --test-objects T [8]        unseen objects for the test (0: every object after the first 16)
  --split-seed Z [0]          the shuffle of the object pool (the same for every run)
  --dataset-seed D [0]        the generator's seed when no --dataset is given
  --max-episode-steps M [250] --warmup-steps W [2000] --updates-per-step U [0.25]
  --buffer-size B [1000000; visual 20000]  --batch-size 256 --lr 3e-4 --hidden 256,256
  --init-alpha A [0.1]        the entropy coefficient's start (it is then tuned)
  --gripper closed|free [closed]  closed: the action is the hand's twist (6 values) and the
                              fingers hold the handle; free: a 7th action opens and closes them
  --checkpoint-interval C [10000] --log-interval L [2000] --quiet
  --device auto|cpu|cuda [auto]  where the networks and updates run (auto: a GPU when PyTorch
                              sees one); not part of the run, which may continue elsewhere

sweep options (the train options above go to every run):
  --tasks, --obs, --train-objects, --seeds   the grid, comma-separated (defaults: the paper's
                              door,drawer x raw,mobility,visual x 2,4,8,16 x 0,1,2)
  --episodes E [20] --eval-seed S [1000]     the evaluation of each run
  --ray auto|ADDRESS          run the runs as Ray tasks (default: one after another here)
  --retries R [3]             times a run is submitted again when its worker is lost
"""


def _parse_options(args, spec):
    """--name value pairs (and flags) into a dict; ValueError naming an unknown or incomplete
    option."""
    out, positional, i = {}, [], 0
    while i < len(args):
        a = args[i]
        if a.startswith("--"):
            name = a[2:]
            if name not in spec:
                raise ValueError(f"unknown option {a}")
            if spec[name] is bool:
                out[name] = True
                i += 1
                continue
            if i + 1 >= len(args):
                raise ValueError(f"option {a} needs a value")
            try:
                out[name] = spec[name](args[i + 1])
            except ValueError:
                raise ValueError(f"option {a}: {args[i + 1]!r} is not a valid value") from None
            i += 2
        else:
            positional.append(a)
            i += 1
    return out, positional


def _hidden(text):
    sizes = tuple(int(x) for x in text.split(","))
    if not sizes or min(sizes) < 1:
        raise ValueError(text)
    return sizes


TRAIN_SPEC = {
    "task": str, "obs": str, "train-objects": int, "steps": int, "seed": int, "out": str,
    "dataset": str, "dataset-seed": int, "split-seed": int, "test-objects": int,
    "num-envs": int, "max-episode-steps": int, "warmup-steps": int, "updates-per-step": float,
    "buffer-size": int, "batch-size": int, "lr": float, "hidden": _hidden, "init-alpha": float,
    "checkpoint-interval": int, "log-interval": int, "quiet": bool, "device": str,
    "gripper": str,
}


def main(argv=None) -> int:
    """``partsim learn`` / ``python3 -m partsim.learn``: returns the exit status (0 done,
    1 a failure, 2 a usage error)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(USAGE, end="")
        return 0 if argv else 2
    command, args = argv[0], argv[1:]
    try:
        if "--help" in args or "-h" in args:
            print(USAGE, end="")
            return 0
        if command == "train":
            opts, positional = _parse_options(args, TRAIN_SPEC)
            if positional:
                raise ValueError(f"train takes no positional arguments ({positional[0]!r})")
            if "out" not in opts:
                raise ValueError("train needs --out RUN")
            fields = {k.replace("-", "_"): v for k, v in opts.items()
                      if k not in ("out", "quiet", "device")}
            if "hidden" in fields:
                fields["hidden_sizes"] = fields.pop("hidden")
            if "dataset" in fields:
                fields["dataset"] = os.path.abspath(fields["dataset"])
            config = RunConfig(**fields)
            summary = train(config, opts["out"], quiet=opts.get("quiet", False),
                            device=opts.get("device", "auto"))
            if summary.get("already_finished"):
                print(f"partsim learn train: {opts['out']!r} is already finished "
                      f"({summary['env_steps']} environment steps for --steps "
                      f"{config.steps}); nothing to do (a larger --steps trains it further)",
                      file=sys.stderr)
            print(json.dumps(summary))
            return 0
        if command == "evaluate":
            opts, positional = _parse_options(
                args, {"episodes": int, "seed": int, "random": bool, "quiet": bool,
                       "shard": str, "results": str, "merge": bool})
            if opts.get("merge"):
                if len(positional) < 2:
                    raise ValueError("evaluate RUN --merge needs the shards' results files")
                if set(opts) - {"merge", "quiet"}:
                    raise ValueError("--merge takes the RUN folder and the shards' files only")
                result = merge_evaluations(positional[0], positional[1:])
            else:
                if len(positional) != 1:
                    raise ValueError("evaluate takes one RUN folder")
                result = evaluate_run(positional[0], episodes=opts.get("episodes", 20),
                                      seed=opts.get("seed", 1000),
                                      policy="random" if opts.get("random") else "agent",
                                      quiet=opts.get("quiet", False), shard=opts.get("shard"),
                                      results=opts.get("results"))
            if "shard" in opts:
                print(f"shard {opts['shard']}: {len(result['objects'])} objects into "
                      f"{opts['results']}")
                return 0
            for part in ("train", "test"):
                r = result[part]
                print(f"{part}: {result['metric']} {r['metric']:.3f}, mean return "
                      f"{r['mean_return']:.2f}, success (90%) {r['success_rate']:.2f} over "
                      f"{len(r['objects'])} objects x {result['episodes']} episodes")
            return 0
        if command == "sweep":
            from ..distributed._sweep import sweep_main

            return sweep_main(args)
        if command == "table":
            opts, positional = _parse_options(args, {"csv": bool})
            if not positional:
                raise ValueError("table needs at least one RUN folder")
            print(table(positional, "csv" if opts.get("csv") else "markdown"), end="")
            return 0
        if command == "curves":
            opts, positional = _parse_options(args, {"out": str, "labels": str})
            if not positional:
                raise ValueError("curves takes one or more RUN folders")
            labels = opts["labels"].split(",") if opts.get("labels") else None
            print(plot_curves(positional[0] if len(positional) == 1 else positional,
                              opts.get("out"), labels))
            return 0
        print(f"partsim learn: unknown command {command!r} (expected train, evaluate, sweep, "
              "table or curves)", file=sys.stderr)
        return 2
    except ValueError as e:
        print(f"partsim learn {command}: {e}", file=sys.stderr)
        return 2
    except ImportError as e:
        if getattr(e, "name", None) in ("torch", "matplotlib"):
            e = f"needs {e.name}: install Debian's python3-{e.name}"
        print(f"partsim learn {command}: {e}", file=sys.stderr)
        return 1
    except RuntimeError as e:  # a sweep's unit that failed, Ray missing
        print(f"partsim learn {command}: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"partsim learn {command}: interrupted (a train run continues from its last "
              "checkpoint when started again)", file=sys.stderr)
        return 130
