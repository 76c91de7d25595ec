"""The training loop of partsim.learn, the same for every task: a vectorised environment
(partsim.envs.VectorOpenCabinetEnv or :class:`SyncVectorEnv`), an agent (:class:`~.sac.SAC`)
and a replay buffer (:class:`~.replay.ReplayBuffer`); plus :func:`evaluate`, deterministic
episodes of a trained agent.

Vector environments follow Gymnasium 1.x's "next-step" autoreset: after a sub-environment's
episode ends, its next ``step`` ignores the action and returns the first observation of a new
episode (reward 0). The trainer stores no transition for such a reset step, and bootstraps on
``terminated`` only (a truncated episode's last state is not terminal).

Resume determinism. A run is cut into segments of ``checkpoint_interval`` environment steps.
Each segment starts with ``env.reset(seed=...)`` with per-environment seeds derived from
(seed, segment index); the episodes still running at the end of a segment are cut there (their
transitions are kept; being cut, they are not counted in the episode statistics). The
checkpoint written at the end of a segment holds the agent, the replay buffer and the loop's
state (counters, the update credit, the statistics accumulated for the next log row, the
numpy generator of the warm-up actions, the length of progress.csv); nothing of the
environment's state is needed, since the next segment begins with a seeded reset. So a run
stopped at any point (a crash, or the end of a shorter ``total_steps``) and resumed with fresh
objects repeats the steps after its last checkpoint exactly as an uninterrupted run does, given
environments whose ``reset(seed=...)`` fixes everything that follows (partsim's do). The end of
a run is a segment end too: a run of 2k steps continued to 4k equals a 4k run when k is a
multiple of the checkpoint interval.

The last row of progress.csv is at the run's last step, also when that is not a multiple of
``log_interval`` (a run shorter than one interval gets that row alone). Such a row sums up the
steps since the previous row, and the last checkpoint keeps it aside. A run continued to more
steps drops it and logs on from the checkpoint's state, as the longer run does. A finished run
resumed as it is writes it back.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import os
import shutil
import sys
import time

import numpy as np
import torch

from .._text import duration as _duration
from .._files import atomic_write as _atomic_write
from ..envs import _stack, _stack_infos, _vector_seeds

__all__ = ["TrainConfig", "Trainer", "SyncVectorEnv", "Evaluation", "evaluate",
           "segment_seeds", "CSV_COLUMNS", "TIMING_COLUMNS"]

# the columns of progress.csv; the timing ones differ from one run to the next
LOSS_KEYS = ("q1_loss", "q2_loss", "policy_loss", "alpha_loss", "alpha", "entropy", "q_mean")
CSV_COLUMNS = ("env_steps", "episodes", "updates", "mean_return", "mean_length",
               "success_rate") + LOSS_KEYS + ("wall_s", "env_steps_per_s", "updates_per_s")
TIMING_COLUMNS = ("wall_s", "env_steps_per_s", "updates_per_s")
POINTER = "checkpoint.json"


@dataclasses.dataclass
class TrainConfig:
    """Options of :class:`Trainer`.

    ``total_steps``: environment steps (stored transitions, summed over the sub-environments;
    autoreset steps are not counted). ``warmup_steps``: the first steps take uniform random
    actions and no update is made. ``updates_per_step``: gradient updates per environment step
    (fractions accumulate). ``checkpoint_interval``: environment steps per segment (see the
    module's docstring; 0: one segment, a checkpoint at the end only). ``log_interval``:
    environment steps between rows of progress.csv and progress lines. ``seed``: of the
    environments' resets and of the warm-up actions (the agent and the buffer have their own).
    ``quiet``: no progress lines on stderr.
    """

    total_steps: int
    warmup_steps: int = 1000
    updates_per_step: float = 1.0
    checkpoint_interval: int = 10000
    log_interval: int = 1000
    seed: int = 0
    quiet: bool = False


def segment_seeds(seed: int, segment: int, num_envs: int) -> list:
    """The reset seeds of the sub-environments at the start of a segment: ``num_envs`` ints
    drawn from ``numpy.random.SeedSequence([seed, segment])``."""
    state = np.random.SeedSequence([int(seed), int(segment)]).generate_state(num_envs, np.uint32)
    return [int(s) for s in state]


def _rows(obs, mask):
    """The rows of a batched observation (array or dict of arrays) where ``mask`` holds."""
    if isinstance(obs, dict):
        return {k: v[mask] for k, v in obs.items()}
    return obs[mask]


def _scale_action(a, space):
    """Actions in [-1, 1] mapped linearly onto the Box ``space``'s bounds."""
    low = np.asarray(space.low, np.float64)
    high = np.asarray(space.high, np.float64)
    if np.all(low == -1.0) and np.all(high == 1.0):
        return a
    return low + (np.asarray(a, np.float64) + 1.0) * 0.5 * (high - low)


def _fmt(x):
    """A CSV cell: repr of floats (round-trips exactly), empty for None or NaN."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    if isinstance(x, float):
        return repr(x)
    return str(x)


class Trainer:
    """Trains ``agent`` on the vector environment ``env`` into the run folder ``out``.

    ``env``: a vector environment with ``num_envs``, ``single_action_space`` (a Box),
    ``reset(seed=list)`` and next-step autoreset (VectorOpenCabinetEnv, SyncVectorEnv);
    ``agent``: with ``act(obs, deterministic)``, ``update(batch) -> dict``, ``state_dict()``,
    ``load_state_dict()`` and ``config.batch_size`` (SAC); ``buffer``: a ReplayBuffer;
    ``config``: a TrainConfig. ``resume``: continue from the run folder's last checkpoint (when
    there is one), with the agent, buffer and environment freshly made as for the first start.

    The folder gets ``progress.csv`` (columns CSV_COLUMNS: per row, the episodes that ended
    since the previous row give mean_return, mean_length and success_rate (from the info key
    ``success``, empty without it); the updates since then give the mean losses; wall_s is the
    training time so far, resumed runs included, and env_steps_per_s and updates_per_s the
    rates since the previous row),
    ``train_config.json`` and the checkpoint (``checkpoint.json`` names the folder
    ``ckpt_<steps>`` holding ``agent.pt``, ``buffer.npz`` and ``loop.json``).
    """

    def __init__(self, env, agent, buffer, out, config: TrainConfig, resume: bool = False):
        self.env, self.agent, self.buffer = env, agent, buffer
        self.out = os.fspath(out)
        self.config = config
        self.resume = bool(resume)
        if config.total_steps < 0 or config.warmup_steps < 0 or config.updates_per_step < 0:
            raise ValueError("TrainConfig: total_steps, warmup_steps and updates_per_step must "
                             "not be negative")
        if config.log_interval < 1 or config.checkpoint_interval < 0:
            raise ValueError("TrainConfig: log_interval must be at least 1 and "
                             "checkpoint_interval at least 0")
        self.num_envs = int(env.num_envs)
        self.action_space = env.single_action_space
        self.action_dim = int(np.prod(self.action_space.shape))
        self.csv_path = os.path.join(self.out, "progress.csv")
        self._fresh_state()

    # --- loop state -------------------------------------------------------------------------

    def _fresh_state(self):
        self.env_steps = 0
        self.episodes = 0
        self.segment = 0
        self.update_credit = 0.0
        self.rng = np.random.default_rng(np.random.SeedSequence([int(self.config.seed), 1]))
        self._window = self._empty_window()
        self.csv_bytes = 0
        self.wall_before = 0.0  # seconds of training before this process's train()
        self._t_start = time.perf_counter()
        # the CSV text of the row written at the run's end past csv_bytes (see the module's
        # docstring), or None
        self._final_row = None

    @staticmethod
    def _empty_window():
        return {"returns": [], "lengths": [], "successes": [], "losses": {},
                "updates": 0}

    def _loop_state(self) -> dict:
        return {
            "env_steps": self.env_steps, "episodes": self.episodes, "segment": self.segment,
            "update_credit": self.update_credit, "rng": self.rng.bit_generator.state,
            "window": self._window, "csv_bytes": self.csv_bytes,
            "wall_s": self.wall_before + time.perf_counter() - self._t_start,
            "config": dataclasses.asdict(self.config), "final_row": self._final_row,
        }

    def _load_loop_state(self, s: dict):
        self.env_steps, self.episodes = int(s["env_steps"]), int(s["episodes"])
        self.segment = int(s["segment"])
        self.update_credit = float(s["update_credit"])
        self.rng.bit_generator.state = s["rng"]
        self._window = s["window"]
        self.csv_bytes = int(s["csv_bytes"])
        self.wall_before = float(s.get("wall_s", 0.0))
        self._final_row = s.get("final_row")

    # --- checkpoints ------------------------------------------------------------------------

    def checkpoint_dir(self):
        """The folder of the last complete checkpoint, or None."""
        pointer = os.path.join(self.out, POINTER)
        if not os.path.isfile(pointer):
            return None
        with open(pointer) as f:
            return os.path.join(self.out, json.load(f)["dir"])

    def save_checkpoint(self):
        """Writes the agent, the buffer and the loop state into a new ``ckpt_<steps>`` folder
        (each file written to a temporary name and renamed), then points ``checkpoint.json``
        at it (atomically) and removes older checkpoint folders."""
        name = f"ckpt_{self.env_steps:012d}"
        d = os.path.join(self.out, name)
        os.makedirs(d, exist_ok=True)
        _atomic_write(os.path.join(d, "agent.pt"),
                      lambda f: torch.save(self.agent.state_dict(), f))
        _atomic_write(os.path.join(d, "buffer.npz"), self.buffer.save)
        loop = json.dumps(self._loop_state()).encode()
        _atomic_write(os.path.join(d, "loop.json"), lambda f: f.write(loop))
        pointer = json.dumps({"dir": name, "env_steps": self.env_steps}).encode()
        _atomic_write(os.path.join(self.out, POINTER), lambda f: f.write(pointer))
        for other in os.listdir(self.out):
            if other.startswith("ckpt_") and other != name:
                shutil.rmtree(os.path.join(self.out, other), ignore_errors=True)

    def load_checkpoint(self) -> bool:
        """Restores the last checkpoint of the run folder into the agent, the buffer and the
        loop state, and cuts progress.csv back to its length then (with the run's final row
        when the checkpoint is at the end of ``total_steps``); False when there is none."""
        d = self.checkpoint_dir()
        if d is None:
            return False
        self.agent.load_state_dict(torch.load(os.path.join(d, "agent.pt"), map_location="cpu"))
        self.buffer.load(os.path.join(d, "buffer.npz"))
        with open(os.path.join(d, "loop.json")) as f:
            self._load_loop_state(json.load(f))
        if os.path.exists(self.csv_path):
            with open(self.csv_path, "r+b") as f:
                f.truncate(self.csv_bytes)
                if self._final_row and self.env_steps >= self.config.total_steps:
                    f.seek(self.csv_bytes)
                    f.write(self._final_row.encode())
        return True

    # --- the loop ---------------------------------------------------------------------------

    def _open_csv(self):
        os.makedirs(self.out, exist_ok=True)
        if not os.path.exists(self.csv_path) or self.csv_bytes == 0:
            with open(self.csv_path, "w", newline="") as f:
                csv.writer(f).writerow(CSV_COLUMNS)
            self.csv_bytes = os.path.getsize(self.csv_path)

    def _reset_env(self):
        obs, _ = self.env.reset(seed=segment_seeds(self.config.seed, self.segment,
                                                   self.num_envs))
        self._ep_return = np.zeros(self.num_envs)
        self._ep_length = np.zeros(self.num_envs, dtype=np.int64)
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)
        return obs

    def train(self) -> dict:
        """Runs (or resumes) the loop until ``total_steps``; returns a summary: env_steps,
        episodes, updates, wall_s, env_steps_per_s, updates_per_s of this call."""
        cfg = self.config
        os.makedirs(self.out, exist_ok=True)
        if self.resume:
            self.load_checkpoint()
        else:
            for old in (POINTER, "progress.csv"):
                if os.path.exists(os.path.join(self.out, old)):
                    os.remove(os.path.join(self.out, old))
        with open(os.path.join(self.out, "train_config.json"), "w") as f:
            json.dump(dataclasses.asdict(cfg), f, indent=1)
        self._open_csv()

        interval = cfg.checkpoint_interval or max(cfg.total_steps, 1)
        next_ckpt = (self.env_steps // interval + 1) * interval
        next_log = (self.env_steps // cfg.log_interval + 1) * cfg.log_interval
        start = self._t_start = time.perf_counter()
        steps0, updates0 = self.env_steps, self.agent.updates
        self._last_log = (start, self.env_steps, self.agent.updates)
        obs = self._reset_env() if self.env_steps < cfg.total_steps else None

        while self.env_steps < cfg.total_steps:
            # act: uniform during the warm-up, the policy's samples after
            if self.env_steps < cfg.warmup_steps:
                action = self.rng.uniform(-1.0, 1.0, (self.num_envs, self.action_dim))
                action = action.astype(np.float32)
            else:
                action = self.agent.act(obs)
            next_obs, reward, terminated, truncated, info = self.env.step(
                _scale_action(action, self.action_space))

            # store the real transitions (not the autoreset steps)
            real = ~self._needs_reset
            if real.any():
                self.buffer.add(_rows(obs, real), action[real], reward[real],
                                _rows(next_obs, real), terminated[real])
            self._ep_return[real] += reward[real]
            self._ep_length[real] += 1
            done = real & (terminated | truncated)
            for i in np.flatnonzero(done):
                self._window["returns"].append(float(self._ep_return[i]))
                self._window["lengths"].append(int(self._ep_length[i]))
                if "success" in info:
                    self._window["successes"].append(bool(info["success"][i]))
                self.episodes += 1
            self._ep_return[~real] = 0.0
            self._ep_length[~real] = 0
            self._needs_reset = done
            obs = next_obs
            n_real = int(real.sum())
            self.env_steps += n_real

            # gradient updates, updates_per_step for each step past the warm-up
            past = self.env_steps - max(cfg.warmup_steps, self.env_steps - n_real)
            if past > 0:
                self.update_credit += cfg.updates_per_step * past
                while self.update_credit >= 1.0:
                    self.update_credit -= 1.0
                    stats = self.agent.update(self.buffer.sample(self.agent.config.batch_size))
                    losses = self._window["losses"]
                    for k, v in stats.items():
                        losses[k] = losses.get(k, 0.0) + float(v)
                    self._window["updates"] += 1

            logged = self.env_steps >= next_log
            if logged:
                self._log_row()
                next_log = (self.env_steps // cfg.log_interval + 1) * cfg.log_interval
            if self.env_steps >= next_ckpt or self.env_steps >= cfg.total_steps:
                self.segment += 1
                self._final_row = None
                if self.env_steps >= cfg.total_steps and not logged:
                    # the run's last step: a row for it, kept out of csv_bytes and the window
                    self._final_row = self._log_row(final=True)
                self.save_checkpoint()
                next_ckpt = (self.env_steps // interval + 1) * interval
                if self.env_steps < cfg.total_steps:
                    obs = self._reset_env()

        wall = time.perf_counter() - start
        steps, updates = self.env_steps - steps0, self.agent.updates - updates0
        return {"env_steps": self.env_steps, "episodes": self.episodes,
                "updates": self.agent.updates, "wall_s": wall,
                "env_steps_per_s": steps / wall if wall > 0 else float("nan"),
                "updates_per_s": updates / wall if wall > 0 else float("nan")}

    def _log_row(self, final=False):
        """Appends a row to progress.csv from the window's statistics, prints a progress line
        and returns the row's text. ``final``: the row at the run's last step, off the log
        interval; csv_bytes, the window and the rates' reference point stay as they were."""
        w = self._window
        now = time.perf_counter()
        t0, s0, u0 = self._last_log
        dt = max(now - t0, 1e-9)
        steps_per_s = (self.env_steps - s0) / dt
        updates_per_s = (self.agent.updates - u0) / dt
        if not final:
            self._last_log = (now, self.env_steps, self.agent.updates)
        row = {
            "env_steps": self.env_steps, "episodes": self.episodes,
            "updates": self.agent.updates,
            "mean_return": float(np.mean(w["returns"])) if w["returns"] else None,
            "mean_length": float(np.mean(w["lengths"])) if w["lengths"] else None,
            "success_rate": float(np.mean(w["successes"])) if w["successes"] else None,
            "wall_s": self.wall_before + now - self._t_start,
            "env_steps_per_s": steps_per_s, "updates_per_s": updates_per_s,
        }
        for k in LOSS_KEYS:
            row[k] = w["losses"][k] / w["updates"] if w["updates"] and k in w["losses"] else None
        buf = io.StringIO()
        csv.writer(buf).writerow([_fmt(row[c]) for c in CSV_COLUMNS])
        data = buf.getvalue().encode()
        with open(self.csv_path, "ab") as f:
            f.write(data)
        if not final:
            self.csv_bytes += len(data)
            self._window = self._empty_window()
        if not self.config.quiet:
            self._print_progress(row, steps_per_s)
        return buf.getvalue()

    def _print_progress(self, row, steps_per_s):
        total = self.config.total_steps
        left = max(total - self.env_steps, 0)
        eta = left / steps_per_s if steps_per_s > 0 else float("inf")
        parts = [f"[partsim.learn] {self.env_steps}/{total} steps "
                 f"({100.0 * self.env_steps / max(total, 1):.1f}%)",
                 f"{steps_per_s:.0f} steps/s", f"{row['updates_per_s']:.0f} updates/s"]
        if row["mean_return"] is not None:
            parts.append(f"return {row['mean_return']:.3g}")
        if row["success_rate"] is not None:
            parts.append(f"success {row['success_rate']:.2f}")
        parts.append("ETA " + _duration(eta))
        print(" | ".join(parts), file=sys.stderr, flush=True)


# --- a generic vector environment --------------------------------------------------------------


class SyncVectorEnv:
    """Single Gymnasium-style environments stepped one after the other as one vector
    environment, with VectorOpenCabinetEnv's conventions: ``reset(seed=...)`` (None, an int
    giving sub-environment i ``seed + i``, or a sequence of seeds) returns stacked observations
    and an info dict of arrays; ``step(actions)`` returns batched ``(obs, rewards,
    terminations, truncations, infos)`` (each info key ``k`` with its mask ``_k``), and after a
    sub-environment's episode ends its next step ignores the action and returns the first
    observation of a new episode (reward 0, neither terminated nor truncated).

    ``envs``: the environments, or callables that make them.
    """

    def __init__(self, envs):
        self.envs = [e() if callable(e) and not hasattr(e, "step") else e for e in envs]
        if not self.envs:
            raise ValueError("SyncVectorEnv needs at least one environment")
        self.num_envs = len(self.envs)
        self.single_observation_space = self.envs[0].observation_space
        self.single_action_space = self.envs[0].action_space
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)

    def reset(self, *, seed=None, options=None):
        """Resets every sub-environment (see the class docstring for ``seed``); returns
        (stacked observations, infos)."""
        seeds = _vector_seeds(seed, self.num_envs)
        results = [e.reset(seed=s, options=options) for e, s in zip(self.envs, seeds)]
        self._needs_reset[:] = False
        return _stack([r[0] for r in results]), self._infos([r[1] for r in results])

    def step(self, actions):
        """Steps every sub-environment with its row of ``actions`` (num_envs, action size),
        resetting instead those whose episode ended at the previous step."""
        actions = np.asarray(actions)
        if actions.shape[0] != self.num_envs:
            raise ValueError(f"actions must have {self.num_envs} rows, got {actions.shape}")
        results = []
        for i, e in enumerate(self.envs):
            if self._needs_reset[i]:
                obs, info = e.reset()
                results.append((obs, 0.0, False, False, info))
            else:
                results.append(e.step(actions[i]))
        terminated = np.array([r[2] for r in results], dtype=bool)
        truncated = np.array([r[3] for r in results], dtype=bool)
        self._needs_reset = terminated | truncated
        return (_stack([r[0] for r in results]),
                np.array([r[1] for r in results], dtype=np.float64), terminated, truncated,
                self._infos([r[4] for r in results]))

    def close(self):
        """Closes every sub-environment that has a ``close``."""
        for e in self.envs:
            if hasattr(e, "close"):
                e.close()

    @staticmethod
    def _infos(items):
        return _stack_infos(items)


# --- evaluation --------------------------------------------------------------------------------


@dataclasses.dataclass
class Evaluation:
    """Results of :func:`evaluate`, one entry per episode: ``returns`` (float), ``lengths``
    (steps) and ``infos`` (the info dict of the episode's last step)."""

    returns: np.ndarray
    lengths: np.ndarray
    infos: list

    @property
    def mean_return(self) -> float:
        """Mean of the episodes' returns."""
        return float(np.mean(self.returns))

    @property
    def success_rate(self):
        """Fraction of episodes whose last info says ``success`` (None without that key)."""
        if not self.infos or "success" not in self.infos[0]:
            return None
        return float(np.mean([bool(i["success"]) for i in self.infos]))


def evaluate(env, agent, episodes: int, seed: int = 0, deterministic: bool = True,
             policy=None) -> Evaluation:
    """Runs ``episodes`` episodes of ``agent`` with deterministic actions (the tanh of the mean)
    and returns their returns, lengths and final infos (an :class:`Evaluation`).

    ``env``: a single environment (episode j starts with ``reset(seed=seed + j)``), a vector
    environment (``num_envs``; reset once with ``seed``, sub-environment i then plays a fixed
    share of the episodes, the first ``ceil`` or ``floor(episodes / num_envs)`` it finishes,
    in order), or a callable that makes either (the environment made is closed afterwards).
    ``policy``: instead of the agent, a function from a batch of observations to actions in
    [-1, 1] (e.g. a random policy for comparison).
    """
    made = callable(env) and not hasattr(env, "step")
    if made:
        env = env()
    act = policy or (lambda o: agent.act(o, deterministic=deterministic))
    try:
        if hasattr(env, "num_envs"):
            return _evaluate_vector(env, act, int(episodes), seed)
        return _evaluate_single(env, act, int(episodes), seed)
    finally:
        if made and hasattr(env, "close"):
            env.close()


def _batch1(obs):
    if isinstance(obs, dict):
        return {k: np.asarray(v)[None] for k, v in obs.items()}
    return np.asarray(obs)[None]


def _evaluate_single(env, act, episodes, seed):
    returns, lengths, infos = [], [], []
    space = env.action_space
    for j in range(episodes):
        obs, info = env.reset(seed=seed + j)
        total, n, done = 0.0, 0, False
        while not done:
            a = _scale_action(np.asarray(act(_batch1(obs)))[0], space)
            obs, r, terminated, truncated, info = env.step(a)
            total += float(r)
            n += 1
            done = terminated or truncated
        returns.append(total)
        lengths.append(n)
        infos.append(info)
    return Evaluation(np.array(returns), np.array(lengths), infos)


def _evaluate_vector(env, act, episodes, seed):
    n_envs = env.num_envs
    wanted = np.array([(episodes + n_envs - 1 - i) // n_envs for i in range(n_envs)])
    got = [[] for _ in range(n_envs)]
    obs, _ = env.reset(seed=seed)
    ret = np.zeros(n_envs)
    length = np.zeros(n_envs, dtype=np.int64)
    needs_reset = np.zeros(n_envs, dtype=bool)
    while any(len(g) < w for g, w in zip(got, wanted)):
        a = _scale_action(np.asarray(act(obs)), env.single_action_space)
        obs, r, terminated, truncated, info = env.step(a)
        real = ~needs_reset
        ret[real] += r[real]
        length[real] += 1
        done = real & (terminated | truncated)
        for i in np.flatnonzero(done):
            if len(got[i]) < wanted[i]:
                got[i].append((float(ret[i]), int(length[i]),
                               {k: v[i] for k, v in info.items() if not k.startswith("_")}))
        ret[~real] = 0.0
        length[~real] = 0
        needs_reset = done
    # sub-environment order, then episode order
    flat = [e for g in got for e in g]
    return Evaluation(np.array([e[0] for e in flat]), np.array([e[1] for e in flat]),
                      [e[2] for e in flat])
