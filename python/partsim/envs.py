"""Gymnasium environments of partsim's drawer-pulling and door-opening tasks.

:class:`OpenCabinetEnv` is a ``gymnasium.Env`` and :class:`VectorOpenCabinetEnv` a
``gymnasium.vector.VectorEnv``; their spaces are ``gymnasium.spaces.Box`` and ``Dict``.
``import partsim`` registers them with Gymnasium as ``partsim/OpenCabinetDrawer-v0``
(``task="drawer"``) and ``partsim/OpenCabinetDoor-v0`` (``task="door"``), 250 steps per
episode; keyword arguments of ``gymnasium.make`` and ``gymnasium.make_vec`` go to the
constructors.

Example::

    import gymnasium as gym
    import partsim  # registers the ids

    env = gym.make("partsim/OpenCabinetDrawer-v0", obs_mode="mobility")
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

    vec = gym.make_vec("partsim/OpenCabinetDoor-v0", num_envs=4,
                       vectorization_mode="vector_entry_point")
    obs, infos = vec.reset(seed=0)
"""

from __future__ import annotations

import concurrent.futures
import functools
import numbers
import os
import warnings
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from . import _partsim as _ps

__all__ = ["OpenCabinetEnv", "VectorOpenCabinetEnv"]


# Scale of the normalised action: a unit action is this TCP speed.
MAX_LINEAR_SPEED = 0.5  # m/s
MAX_ANGULAR_SPEED = 1.5  # rad/s
# Raw observations hold the cabinet's joint positions and velocities padded to this many dof.
RAW_MAX_DOF = 16
ROBOT_STATE_SIZE = 14
# an action in [-1, 1] times this is the task's (TCP twist in m/s and rad/s, gripper command)
_ACTION_SCALE = np.array([MAX_LINEAR_SPEED] * 3 + [MAX_ANGULAR_SPEED] * 3 + [1.0])
OBS_MODES = ("raw", "mobility", "visual")


class OpenCabinetEnv(gymnasium.Env):
    """Drawer pulling (``task="drawer"``) or door opening (``task="door"``) on generated cabinets
    or PartNet-Mobility folders with the flying gripper, as a ``gymnasium.Env``.

    ``objects``: generated StorageFurniture indices (ints, of the generator's ``dataset_seed``)
    and/or PartNet-Mobility folders (str or path-like; real or generated objects whose
    semantics.txt labels a ``drawer`` or a ``rotation_door`` with a handle), one or a list; an
    object without a target for the task raises ``ValueError`` naming it. None: the first
    ``pool_size`` generated objects with a target. Each episode's object is drawn from
    ``objects`` by the environment's generator (``np_random``, which ``reset(seed=...)``
    reseeds), so different seeds give different cabinets and the same seed the same one; each
    object's task is built at its first episode and kept.

    Action: 7 values in [-1, 1]: the gripper's TCP twist in the world frame, scaled by 0.5 m/s
    (linear) and 1.5 rad/s (angular), then the gripper command (-1 close, 1 open). With
    ``gripper_action=False``, 6 values, the twist alone: the fingers stay closed on the handle
    the episode starts on (a policy cannot let go of it). Actions outside [-1, 1] are clipped (a
    documented clamp); NaN or infinite actions, or a wrong shape, raise ``ValueError`` and leave
    the simulation untouched.

    Observation modes (the SAPIEN paper's):

    * ``raw``: the cabinet's joint positions and velocities (each padded with zeros to 16 dof),
      then the robot state (TCP position 3, quaternion wxyz 4, twist 6, gripper opening 1): 46.
    * ``mobility``: the target joint's axis origin (3) and direction (3), the target part's
      average outward normal (3), its joint position and velocity (2), then the robot state: 25.
    * ``visual``: a dict of the front camera's ``rgb`` (h, w, 3) uint8, ``depth`` (h, w) float32
      metres, the target part's ``mask`` (h, w) uint8 and the robot ``state`` (14).

    Reward (dense, as in the paper): 10 x the fraction of the range opened in the step, +1 per
    step once 90% is reached, -0.1 per step that the fingers are off the target after touching
    it (the gripper fell off the handle), and -0.5 x the TCP's distance to the handle until the
    target is first touched. ``terminated`` on success (90% of the range) or
    failure (the part pushed the wrong way); ``truncated`` after ``max_episode_steps``.

    Made by ``gymnasium.make`` (which sets ``spec``), the environment leaves truncation to the
    ``TimeLimit`` wrapper that make adds (the registered 250 steps, or make's
    ``max_episode_steps``; -1 for none), so that the two limits never disagree; made directly,
    it truncates after its own ``max_episode_steps``. ``with env:`` closes it at the end of
    the block.
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
        pool_size: int = 16,
        gripper_action: bool = True,
    ):
        if obs_mode not in OBS_MODES:
            raise ValueError(f"obs_mode must be one of {OBS_MODES}, got {obs_mode!r}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        if max_episode_steps < 1:
            raise ValueError("max_episode_steps must be at least 1")
        if pool_size < 1:
            raise ValueError("pool_size must be at least 1")
        self.task_type = _ps.parse_task_type(task)
        self.obs_mode = obs_mode
        self.render_mode = render_mode
        self.max_episode_steps = int(max_episode_steps)
        if objects is None:
            # the pool: objects with a target, by construction
            self.objects = _ps.find_task_objects(self.task_type, int(pool_size), dataset_seed)
        else:
            if isinstance(objects, (numbers.Integral, str, os.PathLike)):
                objects = [objects]
            self.objects = [
                os.fspath(o) if isinstance(o, (str, os.PathLike)) else int(o) for o in objects
            ]
            if not self.objects:
                raise ValueError(
                    "objects must name at least one StorageFurniture index or PartNet-Mobility "
                    "folder"
                )
            for obj in self.objects:
                if isinstance(obj, str) and not os.path.isfile(os.path.join(obj, "mobility.urdf")):
                    raise ValueError(f"objects: {obj!r} is not a PartNet-Mobility folder")
            _check_targets(self.objects, task, self.task_type, dataset_seed)
        self._options = []
        for obj in self.objects:
            o = _ps.TaskOptions()
            o.type = self.task_type
            if isinstance(obj, str):
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
        self._truncate_at = self.max_episode_steps
        self._closed = False

        self.gripper_action = bool(gripper_action)
        self.action_space = spaces.Box(-1.0, 1.0, (7 if self.gripper_action else 6,), np.float32)
        state = spaces.Box(-np.inf, np.inf, (ROBOT_STATE_SIZE,), np.float32)
        if obs_mode == "raw":
            self.observation_space = spaces.Box(
                -np.inf, np.inf, (2 * RAW_MAX_DOF + ROBOT_STATE_SIZE,), np.float32
            )
        elif obs_mode == "mobility":
            self.observation_space = spaces.Box(
                -np.inf, np.inf, (11 + ROBOT_STATE_SIZE,), np.float32
            )
        else:
            w, h = int(camera_size[0]), int(camera_size[1])
            self.observation_space = spaces.Dict(
                {
                    "rgb": spaces.Box(0, 255, (h, w, 3), np.uint8),
                    "depth": spaces.Box(0.0, np.inf, (h, w), np.float32),
                    "mask": spaces.Box(0, 1, (h, w), np.uint8),
                    "state": state,
                }
            )

    # --- Gymnasium API ---------------------------------------------------------------------

    @property
    def task(self):
        """The current ``ArticulationTask`` (after reset)."""
        return self._task

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Starts an episode. ``seed`` reseeds the environment's generator ``np_random``
        (Gymnasium's ``Env.reset``; same seed, same episode) and the action and observation
        spaces; without it the generator goes on. The generator draws the episode's object, its
        target and the task's seed. ``options`` may hold ``object`` (an index into ``objects``)
        and ``target`` (a drawer or door of that object). Options apply to this episode only: a
        later reset without them draws the object and the target from the generator again."""
        self._check_open()
        super().reset(seed=seed)
        if seed is not None:
            self.action_space.seed(seed)
            self.observation_space.seed(seed)
        options = dict(options or {})
        unknown = set(options) - {"object", "target"}
        if unknown:
            raise ValueError(f"reset: unknown options {sorted(unknown)} (known: object, target)")
        k = options.get("object")
        if k is None:
            k = int(self.np_random.integers(len(self.objects)))
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
        self._task.reset(int(self.np_random.integers(0, 2**62)))
        lo, hi = np.asarray(self._task.target_joint.get_limits(), dtype=float).reshape(-1)[:2]
        self._target_range = float(hi - lo)
        self._steps = 0
        # gymnasium.make sets spec and adds a TimeLimit wrapper, which then truncates alone
        self._truncate_at = self.max_episode_steps if self.spec is None else None
        return self._observation(), self._info()

    def step(self, action):
        """Applies a (7,) action ((6,) without ``gripper_action``) for one control period (1 / control_rate s) and returns
        ``(obs, reward, terminated, truncated, info)``: the observation of ``obs_mode``, the
        dense reward (float), ``terminated`` on success or failure, ``truncated`` after
        ``max_episode_steps`` steps (see the class's note on ``gymnasium.make``), and ``info``
        with ``success``, ``progress`` (fraction of the
        range opened), ``opened`` (how far the target is open: rad for a door, m for a drawer),
        ``object`` (index or folder name), ``target`` (link name), ``touching``
        and ``elapsed`` (simulated s). Raises ``RuntimeError`` before ``reset`` or after
        ``close``, ``ValueError`` for a wrong shape or a non-finite entry."""
        self._check_open()
        if self._task is None:
            raise RuntimeError("step called before reset")
        a = np.asarray(action, dtype=np.float64)
        if a.shape != self.action_space.shape:
            raise ValueError(
                f"action must have shape {self.action_space.shape}, got {a.shape}")
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
        truncated = bool(
            not terminated and self._truncate_at is not None and self._steps >= self._truncate_at
        )
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


def _check_targets(objects, task: str, task_type, dataset_seed: int):
    """Raises ValueError naming the first of ``objects`` (generated indices, or folders that
    hold a mobility.urdf) that has no target for the task: no link labelled
    ``task_target_label`` with a handle (and, for a folder, a joint range)."""
    label = _ps.task_target_label(task_type)
    indices = [o for o in objects if not isinstance(o, str)]
    if indices:
        if min(indices) < 0:
            raise ValueError(f"objects: {min(indices)} is not a StorageFurniture index (< 0)")
        with_target = _indices_with_target(task_type, dataset_seed, max(indices))
    for obj in objects:
        if isinstance(obj, str):
            if _ps.find_task_targets(_ps.PartNetMobilityLoader().parse(obj), task_type):
                continue
            what = f"the PartNet-Mobility folder {obj!r}"
            why = f"no link labelled '{label}' in semantics.txt with a handle and a joint range"
        else:
            if obj in with_target:
                continue
            what = f"StorageFurniture object {obj} (dataset_seed {dataset_seed})"
            why = (
                f"no link labelled '{label}' with a handle; partsim.find_task_objects lists "
                f"the objects that have one"
            )
        raise ValueError(f"objects: {what} has no target for task {task!r} ({why})")


@functools.lru_cache(maxsize=64)
def _indices_with_target(task_type, dataset_seed: int, last: int) -> frozenset:
    """The generated StorageFurniture indices up to ``last`` whose object has a target for the
    task. find_task_objects lists such indices in increasing order, and at most last + 1 of
    them are <= last, so its first last + 1 reach past ``last``."""
    found = _ps.find_task_objects(task_type, last + 1, dataset_seed)
    return frozenset(i for i in found if i <= last)


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


def _autoreset_mode(mode) -> AutoresetMode:
    """An AutoresetMode from itself, its value ("NextStep", "SameStep", "Disabled") or its
    name in any case ("next_step", "SAME_STEP", ...)."""
    if isinstance(mode, AutoresetMode):
        return mode
    if isinstance(mode, str):
        for m in AutoresetMode:
            if mode in (m.value, m.name) or mode.upper() == m.name:
                return m
    names = ", ".join(f"AutoresetMode.{m.name} ({m.value!r})" for m in AutoresetMode)
    raise ValueError(f"autoreset_mode must be one of {names}, got {mode!r}")


def _task_action(a):
    """The task's action for actions in [-1, 1] (clipped), one per row: TCP twist in m/s and
    rad/s, gripper command. Rows of 6 (the twist of ``gripper_action=False``) get the command
    that keeps the fingers closed."""
    if a.shape[-1] == 6:
        a = np.concatenate([a, np.full(a.shape[:-1] + (1,), -1.0)], axis=-1)
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


class VectorOpenCabinetEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` copies of :class:`OpenCabinetEnv` stepped together on ``workers`` threads
    (default: one per copy; the simulation releases the GIL, so the copies run in parallel on
    several cores), as a ``gymnasium.vector.VectorEnv``. The other keyword arguments go to
    every copy. Copy i always runs on thread ``i % workers``: the rasterizer's OpenGL context
    stays current on the thread that last rendered with it, so a scene cannot move between
    threads. Copies without cameras (state observations, no render mode) have no such context:
    ``step`` advances their physics in one ``step_tasks`` call, on up to one thread per core
    without the GIL, which saves a hand-off to a worker per copy and step; their resets still
    run on the workers.

    ``reset`` returns batched observations and an info dict of arrays; ``step(actions)`` with
    actions of shape (num_envs, 7) (6 without ``gripper_action``) returns batched ``(obs, rewards, terminations, truncations,
    infos)``. ``autoreset_mode`` (a ``gymnasium.vector.AutoresetMode`` or its value or name as a
    string; also in ``metadata["autoreset_mode"]``) says what happens after a copy's episode
    ends, as Gymnasium 1.x documents:

    * ``NEXT_STEP`` (default): the copy's next ``step`` ignores its action and returns the
      first observation of a new episode (reward 0, not terminated, not truncated).
    * ``SAME_STEP``: the step that ends the episode resets the copy at once and returns the new
      episode's first observation and info; the last observation and info of the ended episode
      are in ``infos["final_obs"]`` (an object array, None for the other copies) and
      ``infos["final_info"]`` (a dict of arrays), with the masks ``infos["_final_obs"]`` and
      ``infos["_final_info"]``.
    * ``DISABLED``: nothing resets by itself; ``reset(options={"reset_mask": mask})`` resets the
      copies where the bool mask (num_envs,) is True, and ``step`` raises ``RuntimeError`` while
      a copy whose episode ended has not been reset.
    """

    def __init__(
        self,
        num_envs: int,
        workers: int | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        **kwargs,
    ):
        if num_envs < 1:
            raise ValueError("num_envs must be at least 1")
        self.autoreset_mode = _autoreset_mode(autoreset_mode)
        self.metadata = {**OpenCabinetEnv.metadata, "autoreset_mode": self.autoreset_mode}
        self.num_envs = int(num_envs)
        workers = min(int(workers or self.num_envs), self.num_envs)
        if workers < 1:
            raise ValueError("workers must be at least 1")
        self.envs = [OpenCabinetEnv(**kwargs) for _ in range(self.num_envs)]
        self.single_action_space = self.envs[0].action_space
        self.single_observation_space = self.envs[0].observation_space
        self.render_mode = self.envs[0].render_mode
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._threads = [
            concurrent.futures.ThreadPoolExecutor(max_workers=1, thread_name_prefix="partsim-env")
            for _ in range(workers)
        ]
        # copies whose episode ended and that have not been reset since
        self._ended = np.zeros(self.num_envs, dtype=bool)
        # each copy's last observation, for the batch of a partial reset
        self._env_obs = [None] * self.num_envs
        # cameras (visual observations, rgb_array rendering) tie each copy to its thread
        self._gl = any(e._options[0].cameras for e in self.envs)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _check_open(self):
        if self.closed:
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
        """Resets every sub-environment, or with ``options["reset_mask"]`` (a bool numpy array
        of shape (num_envs,) with at least one True) those where the mask is True. ``seed``:
        None, an int (sub-environment i gets ``seed + i``) or a sequence of ``num_envs`` seeds
        (None entries allowed; the entries of the copies not reset are ignored). The other
        options go to every copy's reset. Returns the batched observations (a copy not reset
        keeps its last one) and the infos of the copies reset (the ``_key`` masks say which)."""
        self._check_open()
        seeds = _vector_seeds(seed, self.num_envs)
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None:
            indices = np.arange(self.num_envs)
        else:
            if not isinstance(mask, np.ndarray) or mask.dtype != np.bool_:
                raise TypeError(
                    f"reset: options['reset_mask'] must be a numpy array of bool, got {mask!r}"
                )
            if mask.shape != (self.num_envs,):
                raise ValueError(
                    f"reset: options['reset_mask'] must have shape ({self.num_envs},), got "
                    f"{mask.shape}"
                )
            if not mask.any():
                raise ValueError("reset: options['reset_mask'] resets no sub-environment")
            indices = np.flatnonzero(mask)
            never = [i for i in range(self.num_envs) if self._env_obs[i] is None and not mask[i]]
            if never:
                raise RuntimeError(
                    f"reset: sub-environments {never} were never reset; reset all of them first "
                    f"(reset without reset_mask)"
                )
        results = self._map_some(
            lambda i: self.envs[i].reset(seed=seeds[i], options=options or None), indices
        )
        for i, r in zip(indices, results):
            self._env_obs[i] = r[0]
        self._ended[indices] = False
        if mask is None:
            infos = _stack_infos([r[1] for r in results])
        else:
            infos = {}
            for i, r in zip(indices, results):
                infos = self._add_info(infos, r[1], int(i))
        return _stack(self._env_obs), infos

    def step(self, actions):
        """Steps every sub-environment with its row of ``actions`` (num_envs, 7; 6 without
        ``gripper_action``) and returns batched ``(obs, rewards, terminations, truncations,
        infos)``: observations stacked
        along a first axis of num_envs, rewards float64 (num_envs,), terminations and
        truncations bool (num_envs,), infos a dict of arrays (each key ``k`` with a bool mask
        ``_k``). Episodes that end are reset as ``autoreset_mode`` says (see the class).
        Raises ``ValueError`` for a wrong shape or non-finite actions, ``RuntimeError``
        before ``reset``, after ``close`` or (``DISABLED``) while an ended episode is not
        reset."""
        self._check_open()
        actions = np.asarray(actions, dtype=np.float64)
        want = (self.num_envs,) + self.single_action_space.shape
        if actions.shape != want:
            raise ValueError(f"actions must have shape {want}, got {actions.shape}")
        if not np.all(np.isfinite(actions)):
            raise ValueError("actions hold NaN or infinite values")
        # which copies start a new episode instead of stepping (next-step autoreset)
        if self.autoreset_mode is AutoresetMode.NEXT_STEP:
            restart = self._ended
        else:
            if self._ended.any():
                raise RuntimeError(
                    f"step: the episodes of sub-environments {np.flatnonzero(self._ended).tolist()}"
                    f" ended and autoreset_mode is DISABLED: reset them first with "
                    f"reset(options={{'reset_mask': mask}})"
                )
            restart = np.zeros(self.num_envs, dtype=bool)

        def one(i):
            env = self.envs[i]
            if restart[i]:
                obs, info = env.reset()
                return obs, 0.0, False, False, info
            return env.step(actions[i])

        if self._gl:
            results = self._map(one)
        else:
            # no OpenGL context to keep on its thread: the resets on the workers, then every
            # other copy's physics in one call that steps them on up to a thread per core
            results = [None] * self.num_envs
            resets = np.flatnonzero(restart)
            if len(resets):
                for i, r in zip(resets, self._map_some(one, resets)):
                    results[i] = r
            rest = np.flatnonzero(~restart)
            if len(rest):
                envs = [self.envs[i] for i in rest]
                if any(e._task is None for e in envs):
                    raise RuntimeError("step called before reset")
                _ps.step_tasks([e._task for e in envs], _task_action(actions[rest]))
                for i, e in zip(rest, envs):
                    results[i] = e._after_step()
        terminated = np.array([r[2] for r in results], dtype=bool)
        truncated = np.array([r[3] for r in results], dtype=bool)
        self._ended = terminated | truncated
        obs = [r[0] for r in results]
        infos = [r[4] for r in results]
        final = None
        if self.autoreset_mode is AutoresetMode.SAME_STEP and self._ended.any():
            # the ended episodes' last observation and info go to final_obs / final_info; the
            # copies start their next episode in this step
            final = np.flatnonzero(self._ended)
            last = [(obs[i], infos[i]) for i in final]
            for i, (o, info) in zip(final, self._map_some(lambda i: self.envs[i].reset(), final)):
                obs[i], infos[i] = o, info
            self._ended[:] = False
        self._env_obs = obs
        infos = _stack_infos(infos)
        if final is not None:
            for i, (o, info) in zip(final, last):
                infos = self._add_info(infos, {"final_obs": o, "final_info": info}, int(i))
        return (
            _stack(obs),
            np.array([r[1] for r in results], dtype=np.float64),
            terminated,
            truncated,
            infos,
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

    def close_extras(self, **kwargs):
        """Closes every sub-environment on its own thread and stops the threads (``close``,
        Gymnasium's, calls it once; closing twice does nothing)."""
        self._map(lambda i: self.envs[i].close())  # frees the GL objects on their thread
        for t in self._threads:
            t.shutdown(wait=True)
