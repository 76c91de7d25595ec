"""Gymnasium-style environments of partsim's drawer-pulling and door-opening tasks.

The classes follow the Gymnasium API (``reset(seed=..., options=...)`` returns ``(obs, info)``;
``step(action)`` returns ``(obs, reward, terminated, truncated, info)``; ``observation_space``,
``action_space``, ``render()``, ``close()``) without importing the gymnasium package, which is
not installable everywhere: the spaces here (``Box``, ``Dict``) have the same attributes and
methods as Gymnasium's. A gymnasium user can wrap an instance with ``gymnasium.Env`` conventions
directly.

Example::

    import partsim.envs as envs
    env = envs.OpenCabinetEnv(task="drawer", obs_mode="mobility")
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

import concurrent.futures
import numbers
import os
import warnings
from typing import Any

import numpy as np

from . import _partsim as _ps

__all__ = ["Box", "Dict", "OpenCabinetEnv", "VectorOpenCabinetEnv"]


class Box:
    """A box in R^n: ``low <= x <= high`` elementwise, with a shape and dtype (Gymnasium's
    ``spaces.Box``)."""

    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):
        self.dtype = np.dtype(dtype)
        if shape is None:
            shape = np.shape(low) if np.ndim(low) else np.shape(high)
        self.shape = tuple(int(s) for s in shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape).copy()
        if np.any(self.low > self.high):
            raise ValueError("Box: low exceeds high")
        self._rng = np.random.default_rng(seed)

    def seed(self, seed=None):
        """Reseeds the generator that ``sample`` draws from (None: fresh entropy); returns
        ``[seed]``."""
        self._rng = np.random.default_rng(seed)
        return [seed]

    @property
    def np_random(self):
        """The ``numpy.random.Generator`` that ``sample`` draws from."""
        return self._rng

    def sample(self, mask=None):
        """A uniform sample (bounded dimensions), normal (unbounded), exponential (half-bounded),
        as Gymnasium does."""
        if np.issubdtype(self.dtype, np.integer):
            return self._rng.integers(self.low, self.high, endpoint=True).astype(self.dtype)
        low, high = self.low.astype(np.float64), self.high.astype(np.float64)
        out = np.empty(self.shape)
        bounded = np.isfinite(low) & np.isfinite(high)
        lower_only = np.isfinite(low) & ~np.isfinite(high)
        upper_only = ~np.isfinite(low) & np.isfinite(high)
        free = ~np.isfinite(low) & ~np.isfinite(high)
        out[bounded] = self._rng.uniform(low[bounded], high[bounded])
        out[lower_only] = low[lower_only] + self._rng.exponential(size=lower_only.sum())
        out[upper_only] = high[upper_only] - self._rng.exponential(size=upper_only.sum())
        out[free] = self._rng.normal(size=free.sum())
        return out.astype(self.dtype)

    def contains(self, x) -> bool:
        """True when ``x`` (an array or anything ``numpy.asarray`` takes) has this shape, a
        dtype that casts safely to this dtype, and every entry within ``[low, high]``."""
        if not isinstance(x, np.ndarray):
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError, OverflowError):
                return False
        return bool(
            np.can_cast(x.dtype, self.dtype)
            and x.shape == self.shape
            and np.all(x >= self.low)
            and np.all(x <= self.high)
        )

    def __contains__(self, x) -> bool:
        return self.contains(x)

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"

    def __eq__(self, other):
        return (
            isinstance(other, Box)
            and self.shape == other.shape
            and self.dtype == other.dtype
            and np.array_equal(self.low, other.low)
            and np.array_equal(self.high, other.high)
        )


class Dict:
    """A dictionary of spaces (Gymnasium's ``spaces.Dict``)."""

    def __init__(self, spaces: dict, seed=None):
        self.spaces = dict(spaces)
        self.shape = None
        self.dtype = None
        self.seed(seed)

    def seed(self, seed=None):
        """Reseeds every sub-space from one ``numpy.random.SeedSequence(seed)`` (a child seed
        each); returns ``[seed]``."""
        ss = np.random.SeedSequence(seed)
        for space, child in zip(self.spaces.values(), ss.spawn(len(self.spaces))):
            space.seed(int(child.generate_state(1)[0]))
        return [seed]

    def sample(self, mask=None):
        """A dict with one sample of each sub-space (``mask`` is accepted and ignored)."""
        return {k: s.sample() for k, s in self.spaces.items()}

    def contains(self, x) -> bool:
        """True when ``x`` is a dict with exactly these keys and each value lies in its
        sub-space."""
        return (
            isinstance(x, dict)
            and x.keys() == self.spaces.keys()
            and all(s.contains(x[k]) for k, s in self.spaces.items())
        )

    def __contains__(self, x) -> bool:
        return self.contains(x)

    def __getitem__(self, key):
        return self.spaces[key]

    def __iter__(self):
        return iter(self.spaces)

    def __len__(self):
        return len(self.spaces)

    def keys(self):
        """The sub-spaces' names."""
        return self.spaces.keys()

    def values(self):
        """The sub-spaces (``Box`` or ``Dict``)."""
        return self.spaces.values()

    def items(self):
        """(name, sub-space) pairs."""
        return self.spaces.items()

    def __eq__(self, other):
        return isinstance(other, Dict) and self.spaces == other.spaces

    def __repr__(self):
        return "Dict(" + ", ".join(f"{k!r}: {s}" for k, s in self.spaces.items()) + ")"


# Scale of the normalised action: a unit action is this TCP speed.
MAX_LINEAR_SPEED = 0.5  # m/s
MAX_ANGULAR_SPEED = 1.5  # rad/s
# Raw observations hold the cabinet's joint positions and velocities padded to this many dof.
RAW_MAX_DOF = 16
ROBOT_STATE_SIZE = 14
# an action in [-1, 1] times this is the task's (TCP twist in m/s and rad/s, gripper command)
_ACTION_SCALE = np.array([MAX_LINEAR_SPEED] * 3 + [MAX_ANGULAR_SPEED] * 3 + [1.0])
OBS_MODES = ("raw", "mobility", "visual")


class _ClosedByContext:
    """``with env:`` closes the environment at the end of the block."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


class OpenCabinetEnv(_ClosedByContext):
    """Drawer pulling (``task="drawer"``) or door opening (``task="door"``) on generated cabinets
    or PartNet-Mobility folders with the flying gripper.

    ``objects``: generated StorageFurniture indices (ints) and/or PartNet-Mobility folders (str or
    path-like; real or generated objects whose semantics.txt labels a ``drawer`` or a
    ``rotation_door`` with a handle), one or a list; None takes the first generated object with a
    target.

    Action: 7 values in [-1, 1]: the gripper's TCP twist in the world frame, scaled by 0.5 m/s
    (linear) and 1.5 rad/s (angular), then the gripper command (-1 close, 1 open). Actions outside
    [-1, 1] are clipped (a documented clamp); NaN or infinite actions, or a wrong shape, raise
    ``ValueError`` and leave the simulation untouched.

    Observation modes (the SAPIEN paper's):

    * ``raw``: the cabinet's joint positions and velocities (each padded with zeros to 16 dof),
      then the robot state (TCP position 3, quaternion wxyz 4, twist 6, gripper opening 1): 46.
    * ``mobility``: the target joint's axis origin (3) and direction (3), the target part's
      average outward normal (3), its joint position and velocity (2), then the robot state: 25.
    * ``visual``: a dict of the front camera's ``rgb`` (h, w, 3) uint8, ``depth`` (h, w) float32
      metres, the target part's ``mask`` (h, w) uint8 and the robot ``state`` (14).

    Reward (dense, as in the paper): 10 x the fraction of the range opened in the step, +1 per
    step once 90% is reached, -0.1 when a held grasp is lost, and -0.5 x the TCP's distance to
    the handle until the target is first touched. ``terminated`` on success (90% of the range) or
    failure (the part pushed the wrong way); ``truncated`` after ``max_episode_steps``.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(
        self,
        task: str = "drawer",
        obs_mode: str = "mobility",
        objects=None,
        dataset_seed: int = 0,
        max_episode_steps: int = 250,
        control_rate: float = 25.0,
        init_on_handle: bool = True,
        render_mode: str | None = None,
        camera_size=(128, 96),
        render_backend: str = "rasterizer",
    ):
        if obs_mode not in OBS_MODES:
            raise ValueError(f"obs_mode must be one of {OBS_MODES}, got {obs_mode!r}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        if max_episode_steps < 1:
            raise ValueError("max_episode_steps must be at least 1")
        self.task_type = _ps.parse_task_type(task)
        self.obs_mode = obs_mode
        self.render_mode = render_mode
        self.max_episode_steps = int(max_episode_steps)
        if objects is None:
            objects = _ps.find_task_objects(self.task_type, 1, dataset_seed)
        elif isinstance(objects, (numbers.Integral, str, os.PathLike)):
            objects = [objects]
        self.objects = [
            os.fspath(o) if isinstance(o, (str, os.PathLike)) else int(o) for o in objects
        ]
        if not self.objects:
            raise ValueError(
                "objects must name at least one StorageFurniture index or PartNet-Mobility folder"
            )
        self._options = []
        for obj in self.objects:
            o = _ps.TaskOptions()
            o.type = self.task_type
            if isinstance(obj, str):
                if not os.path.isfile(os.path.join(obj, "mobility.urdf")):
                    raise ValueError(f"objects: {obj!r} is not a PartNet-Mobility folder")
                o.object_folder = obj
            else:
                o.object_index = obj
            o.dataset_seed = dataset_seed
            o.control_rate = control_rate
            o.max_seconds = max_episode_steps / control_rate + 1.0
            o.init_on_handle = init_on_handle
            o.cameras = obs_mode == "visual" or render_mode == "rgb_array"
            o.camera_width, o.camera_height = int(camera_size[0]), int(camera_size[1])
            o.render_backend = render_backend
            self._options.append(o)
        # one task per (object, target), target -1 meaning "drawn by reset's seed"
        self._tasks: dict[tuple[int, int], Any] = {}
        self._task = None
        self._steps = 0
        self._np_random = np.random.default_rng()
        self._closed = False

        self.action_space = Box(-1.0, 1.0, (7,), np.float32)
        state = Box(-np.inf, np.inf, (ROBOT_STATE_SIZE,), np.float32)
        if obs_mode == "raw":
            self.observation_space = Box(
                -np.inf, np.inf, (2 * RAW_MAX_DOF + ROBOT_STATE_SIZE,), np.float32
            )
        elif obs_mode == "mobility":
            self.observation_space = Box(-np.inf, np.inf, (11 + ROBOT_STATE_SIZE,), np.float32)
        else:
            w, h = int(camera_size[0]), int(camera_size[1])
            self.observation_space = Dict(
                {
                    "rgb": Box(0, 255, (h, w, 3), np.uint8),
                    "depth": Box(0.0, np.inf, (h, w), np.float32),
                    "mask": Box(0, 1, (h, w), np.uint8),
                    "state": state,
                }
            )

    # --- Gymnasium API ---------------------------------------------------------------------

    @property
    def np_random(self) -> np.random.Generator:
        """The environment's ``numpy.random.Generator``: it draws each episode's object, target
        and task seed; ``reset(seed=...)`` reseeds it."""
        return self._np_random

    @property
    def unwrapped(self):
        """The environment itself (Gymnasium's ``Env.unwrapped``; there are no wrappers)."""
        return self

    @property
    def task(self):
        """The current ``ArticulationTask`` (after reset)."""
        return self._task

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Starts an episode. ``seed`` reseeds the environment's generator (same seed, same
        episode); ``options`` may hold ``object`` (an index into ``objects``) and ``target`` (a
        drawer or door of that object). Options apply to this episode only: a later reset
        without them draws the object and the target from the generator again."""
        self._check_open()
        if seed is not None:
            self._np_random = np.random.default_rng(seed)
            self.action_space.seed(seed)
            self.observation_space.seed(seed)
        options = dict(options or {})
        unknown = set(options) - {"object", "target"}
        if unknown:
            raise ValueError(f"reset: unknown options {sorted(unknown)} (known: object, target)")
        k = options.get("object")
        if k is None:
            k = int(self._np_random.integers(len(self.objects)))
        if not isinstance(k, numbers.Integral) or not 0 <= k < len(self.objects):
            raise ValueError(f"reset: options['object'] = {k} is not in [0, {len(self.objects)})")
        k = int(k)
        target = options.get("target", -1)
        if not isinstance(target, numbers.Integral) or target < -1:
            raise ValueError(f"reset: options['target'] = {target} is not a target index")
        key = (k, int(target))
        if key not in self._tasks:
            opts = self._options[k]
            opts.target = key[1]
            try:  # an out-of-range target raises PartsimError, a ValueError
                self._tasks[key] = _ps.ArticulationTask(opts)
            finally:
                opts.target = -1
        self._task = self._tasks[key]
        self._task.reset(int(self._np_random.integers(0, 2**62)))
        lo, hi = np.asarray(self._task.target_joint.get_limits(), dtype=float).reshape(-1)[:2]
        self._target_range = float(hi - lo)
        self._steps = 0
        return self._observation(), self._info()

    def step(self, action):
        """Applies a (7,) action for one control period (1 / control_rate s) and returns
        ``(obs, reward, terminated, truncated, info)``: the observation of ``obs_mode``, the
        dense reward (float), ``terminated`` on success or failure, ``truncated`` after
        ``max_episode_steps`` steps, and ``info`` with ``success``, ``progress`` (fraction of the
        range opened), ``opened`` (how far the target is open: rad for a door, m for a drawer),
        ``object`` (index or folder name), ``target`` (link name), ``touching``
        and ``elapsed`` (simulated s). Raises ``RuntimeError`` before ``reset`` or after
        ``close``, ``ValueError`` for a wrong shape or a non-finite entry."""
        self._check_open()
        if self._task is None:
            raise RuntimeError("step called before reset")
        a = np.asarray(action, dtype=np.float64)
        if a.shape != (7,):
            raise ValueError(f"action must have shape (7,), got {a.shape}")
        if not np.all(np.isfinite(a)):
            bad = int(np.flatnonzero(~np.isfinite(a))[0])
            raise ValueError(f"action entry {bad} is not finite ({a[bad]})")
        self._task.apply_action(_task_action(a))
        self._task.step()
        return self._after_step()

    def _after_step(self):
        """step's result once the task has stepped."""
        self._steps += 1
        reward = float(self._task.get_reward())
        terminated = bool(self._task.is_success() or self._task.is_failure())
        truncated = bool(not terminated and self._steps >= self.max_episode_steps)
        return self._observation(), reward, terminated, truncated, self._info()

    def render(self):
        """The front camera's colour as (h, w, 3) uint8 (render_mode 'rgb_array')."""
        self._check_open()
        if self.render_mode != "rgb_array":
            _warn_no_render_mode(type(self).__name__)
            return None
        if self._task is None:
            raise RuntimeError("render called before reset")
        if self.obs_mode != "visual" or self._last_picture_step != self._steps:
            self._front_picture()
        return np.ascontiguousarray(self._task.get_camera("front").get_color_rgba8()[:, :, :3])

    def close(self):
        """Frees the tasks and their scenes; later calls other than ``close`` raise
        ``RuntimeError``."""
        self._tasks.clear()
        self._task = None
        self._closed = True

    # --- internals ---------------------------------------------------------------------------

    _last_picture_step = -1

    def _check_open(self):
        if self._closed:
            raise RuntimeError("the environment is closed")

    def _front_picture(self):
        """Renders the front camera only (the task's take_pictures renders all three, four
        times the work) and returns that camera."""
        self._task.scene.update_render()
        cam = self._task.get_camera("front")
        cam.take_picture()
        return cam

    def _info(self) -> dict:
        t = self._task
        return {
            "success": bool(t.is_success()),
            "progress": float(t.get_progress()),
            "object": (
                os.path.basename(os.path.normpath(t.options.object_folder))
                if t.options.object_folder
                else int(t.options.object_index)
            ),
            "target": t.target_link.get_name(),
            "opened": float(t.get_progress() * self._target_range),
            "touching": bool(t.gripper_touches_target()),
            "elapsed": float(t.get_elapsed()),
        }

    def _observation(self):
        t = self._task
        if self.obs_mode == "raw":
            qpos, qvel = t.object.get_qpos(), t.object.get_qvel()
            n = len(qpos)
            if n > RAW_MAX_DOF:
                raise RuntimeError(
                    f"cabinet has {n} dof, more than the raw observation's {RAW_MAX_DOF}"
                )
            out = np.zeros(2 * RAW_MAX_DOF + ROBOT_STATE_SIZE, dtype=np.float32)
            out[:n] = qpos
            out[RAW_MAX_DOF : RAW_MAX_DOF + n] = qvel
            out[2 * RAW_MAX_DOF :] = t.get_raw_observation()[2 * n :]
            return out
        if self.obs_mode == "mobility":
            return np.asarray(t.get_mobility_observation(), dtype=np.float32)
        cam = self._front_picture()
        self._last_picture_step = self._steps
        seg = cam.get_picture("Segmentation")
        depth = np.asarray(cam.get_depth(), dtype=np.float32)
        return {
            "rgb": np.ascontiguousarray(cam.get_color_rgba8()[:, :, :3]),
            "depth": np.ascontiguousarray(depth),
            "mask": (seg[:, :, 1] == t.get_target_entity_id()).astype(np.uint8),
            "state": np.asarray(t.get_raw_observation()[-ROBOT_STATE_SIZE:], dtype=np.float32),
        }


def _batch_space(space, n):
    """The space of ``n`` stacked samples of ``space`` (Gymnasium's ``batch_space``)."""
    if isinstance(space, Dict):
        return Dict({k: _batch_space(s, n) for k, s in space.items()})
    return Box(
        np.broadcast_to(space.low, (n,) + space.shape),
        np.broadcast_to(space.high, (n,) + space.shape),
        (n,) + space.shape,
        space.dtype,
    )


def _stack(items):
    """One batched observation from a list of them (arrays, or dicts of arrays)."""
    if isinstance(items[0], dict):
        return {k: np.stack([x[k] for x in items]) for k in items[0]}
    return np.stack(items)


def _stack_infos(items):
    """Gymnasium's vector info dict from a list of info dicts: an array per key, and a
    ``_key`` mask saying which sub-environments have it (all of them here)."""
    out = {}
    for k in items[0]:
        out[k] = np.array([x[k] for x in items])
        out["_" + k] = np.ones(len(items), dtype=bool)
    return out


def _vector_seeds(seed, num_envs: int) -> list:
    """The reset seeds of ``num_envs`` sub-environments from a vector reset's ``seed``: None
    for all, ``seed + i`` for an int, or a sequence of ``num_envs`` seeds as given."""
    if seed is None:
        return [None] * num_envs
    if isinstance(seed, numbers.Integral):
        return [int(seed) + i for i in range(num_envs)]
    seeds = list(seed)
    if len(seeds) != num_envs:
        raise ValueError(f"reset: {len(seeds)} seeds for {num_envs} environments")
    return seeds


def _task_action(a):
    """The task's action for actions in [-1, 1] (clipped), one per row: TCP twist in m/s and
    rad/s, gripper command."""
    # np.minimum / np.maximum: np.clip's Python wrapper costs more than the rest of this
    return np.minimum(np.maximum(a, -1.0), 1.0) * _ACTION_SCALE


def _warn_no_render_mode(cls_name):
    warnings.warn(
        f"{cls_name}.render() returns None: the environment was made without a render mode; "
        f"make it with render_mode=\"rgb_array\" to get frames, e.g. "
        f"{cls_name}(..., render_mode=\"rgb_array\")",
        UserWarning,
        stacklevel=3,
    )


class VectorOpenCabinetEnv(_ClosedByContext):
    """``num_envs`` copies of :class:`OpenCabinetEnv` stepped together on ``workers`` threads
    (default: one per copy; the simulation releases the GIL, so the copies run in parallel on
    several cores). Copy i always runs on thread ``i % workers``: the rasterizer's OpenGL context
    stays current on the thread that last rendered with it, so a scene cannot move between
    threads. Copies without cameras (state observations, no render mode) have no such context:
    ``step`` advances their physics in one ``step_tasks`` call, a thread per copy without the
    GIL, which saves a hand-off to a worker per copy and step; their resets still run on the
    workers.

    Follows Gymnasium's vector API: ``reset`` returns batched observations and an info dict of
    arrays; ``step(actions)`` with actions of shape (num_envs, 7) returns batched
    ``(obs, rewards, terminations, truncations, infos)``. Autoreset is Gymnasium 1.x's
    "next-step" mode: after a sub-environment's episode ends, its next ``step`` ignores the
    action and returns the first observation of a new episode (reward 0, not terminated).
    """

    metadata = OpenCabinetEnv.metadata

    def __init__(self, num_envs: int, workers: int | None = None, **kwargs):
        if num_envs < 1:
            raise ValueError("num_envs must be at least 1")
        self.num_envs = int(num_envs)
        self.envs = [OpenCabinetEnv(**kwargs) for _ in range(self.num_envs)]
        self.single_action_space = self.envs[0].action_space
        self.single_observation_space = self.envs[0].observation_space
        self.render_mode = self.envs[0].render_mode
        self.action_space = _batch_space(self.single_action_space, self.num_envs)
        self.observation_space = _batch_space(self.single_observation_space, self.num_envs)
        workers = min(int(workers or self.num_envs), self.num_envs)
        if workers < 1:
            raise ValueError("workers must be at least 1")
        self._threads = [
            concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="partsim-env")
            for _ in range(workers)
        ]
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)
        # cameras (visual observations, rgb_array rendering) tie each copy to its thread
        self._gl = any(e._options[0].cameras for e in self.envs)
        self._closed = False

    def _check_open(self):
        if self._closed:
            raise RuntimeError("the vector environment is closed")

    def _map(self, fn):
        """[fn(i) for each sub-environment i], each on its own thread."""
        return self._map_some(fn, range(self.num_envs))

    def _map_some(self, fn, indices):
        """[fn(i) for i in indices], each on sub-environment i's thread."""
        n = len(self._threads)
        futures = [self._threads[int(i) % n].submit(fn, int(i)) for i in indices]
        return [f.result() for f in futures]

    def reset(self, *, seed=None, options=None):
        """Resets every sub-environment: ``seed`` None, an int (sub-environment i gets
        ``seed + i``) or a sequence of ``num_envs`` seeds (None entries allowed)."""
        self._check_open()
        seeds = _vector_seeds(seed, self.num_envs)
        results = self._map(lambda i: self.envs[i].reset(seed=seeds[i], options=options))
        self._needs_reset[:] = False
        return _stack([r[0] for r in results]), self._infos([r[1] for r in results])

    def step(self, actions):
        """Steps every sub-environment with its row of ``actions`` (num_envs, 7) and returns
        batched ``(obs, rewards, terminations, truncations, infos)``: observations stacked
        along a first axis of num_envs, rewards float64 (num_envs,), terminations and
        truncations bool (num_envs,), infos a dict of arrays (each key ``k`` with a bool mask
        ``_k``). A sub-environment whose episode ended is reset instead (next-step autoreset).
        Raises ``ValueError`` for a wrong shape or non-finite actions."""
        self._check_open()
        actions = np.asarray(actions, dtype=np.float64)
        if actions.shape != (self.num_envs, 7):
            raise ValueError(f"actions must have shape ({self.num_envs}, 7), got {actions.shape}")
        if not np.all(np.isfinite(actions)):
            raise ValueError("actions hold NaN or infinite values")

        def one(i):
            env = self.envs[i]
            if self._needs_reset[i]:
                obs, info = env.reset()
                return obs, 0.0, False, False, info
            return env.step(actions[i])

        if self._gl:
            results = self._map(one)
        else:
            # no OpenGL context to keep on its thread: the resets on the workers, then every
            # other copy's physics in one call that steps them on a thread each
            results = [None] * self.num_envs
            resets = np.flatnonzero(self._needs_reset)
            if len(resets):
                for i, r in zip(resets, self._map_some(one, resets)):
                    results[i] = r
            rest = np.flatnonzero(~self._needs_reset)
            if len(rest):
                envs = [self.envs[i] for i in rest]
                if any(e._task is None for e in envs):
                    raise RuntimeError("step called before reset")
                _ps.step_tasks([e._task for e in envs], _task_action(actions[rest]))
                for i, e in zip(rest, envs):
                    results[i] = e._after_step()
        terminated = np.array([r[2] for r in results], dtype=bool)
        truncated = np.array([r[3] for r in results], dtype=bool)
        self._needs_reset = terminated | truncated
        return (
            _stack([r[0] for r in results]),
            np.array([r[1] for r in results], dtype=np.float64),
            terminated,
            truncated,
            self._infos([r[4] for r in results]),
        )

    def render(self):
        """The front camera's colour of every sub-environment, as a tuple of ``num_envs``
        (h, w, 3) uint8 arrays (render_mode ``"rgb_array"``, given to the constructor with the
        other keyword arguments); each is rendered on its sub-environment's own thread. Without
        a render mode it warns and returns None, as a single environment does. Raises
        ``RuntimeError`` before ``reset``."""
        self._check_open()
        if self.render_mode != "rgb_array":
            _warn_no_render_mode(type(self).__name__)
            return None
        return tuple(self._map(lambda i: self.envs[i].render()))

    def close(self):
        """Closes every sub-environment on its own thread and stops the threads; closing twice
        does nothing."""
        if self._closed:
            return
        self._map(lambda i: self.envs[i].close())  # frees the GL objects on their thread
        for t in self._threads:
            t.shutdown(wait=True)
        self._closed = True

    @staticmethod
    def _infos(items):
        return _stack_infos(items)
