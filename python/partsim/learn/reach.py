"""A small reaching task on a real partsim scene, small enough for SAC to learn within the test
suite's budget: a planar arm of one or two links turning about vertical joints, driven by joint
velocity targets, has to bring its tip to a target drawn per episode.

It is a Gymnasium environment, with partsim.envs' conventions (``reset(seed=...) -> (obs,
info)``, ``step(action) -> (obs, reward, terminated, truncated, info)``, ``observation_space``
and ``action_space`` as gymnasium.spaces.Box), so other learners (Stable-Baselines3's SAC in
the tests) train on it as they are, and :func:`make_reach_vector_env` batches copies of it with the trainer's
:class:`~.trainer.SyncVectorEnv` (next-step autoreset, as VectorOpenCabinetEnv), so that the
trainer runs here on the code path of the real tasks.
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium.spaces import Box

from .. import _partsim as _ps
from .trainer import SyncVectorEnv

__all__ = ["ReachEnv", "make_reach_vector_env"]

# the joint frame's x axis (the joint axis) along the parent's z: a rotation of -90 deg about y
_X_TO_Z = _ps.Pose([0, 0, 0], [0.7071067811865476, 0, -0.7071067811865476, 0])


class ReachEnv(gymnasium.Env):
    """Tip reaching with a planar arm of ``dof`` (1 or 2) links of ``link_length`` m on
    continuous joints about the world's z axis (no gravity along them; no collisions).

    Action: ``dof`` values in [-1, 1] (clipped), the joints' velocity targets in units of
    ``max_joint_speed`` rad/s, held by velocity drives for one control period
    (1 / ``control_rate`` s, ``substeps`` physics steps).

    Observation (float32): cos and sin of the joint angles (2 dof), joint velocities divided
    by max_joint_speed (dof), the tip's x, y (2), the target's x, y (2) and target - tip (2),
    in metres in the arm's base frame: 6 + 3 dof values.

    Episode: the joints start at uniform angles, at rest; the target is drawn uniformly from the
    reachable annulus (2 dof: radii from 0.25 to 0.95 of the arm's reach; 1 dof: the tip's
    circle). Reward: minus the tip's distance to the target (m) at each step.
    ``terminated`` when the distance is below ``tolerance`` (success); ``truncated`` after
    ``max_episode_steps``. ``info``: ``success`` and ``distance``.
    """

    metadata = {"render_modes": [], "render_fps": 20}

    def __init__(self, dof: int = 2, link_length: float = 0.3, max_episode_steps: int = 50,
                 control_rate: float = 20.0, substeps: int = 5, max_joint_speed: float = 3.0,
                 tolerance: float = 0.05):
        if dof not in (1, 2):
            raise ValueError(f"ReachEnv: dof must be 1 or 2, got {dof}")
        if max_episode_steps < 1 or substeps < 1:
            raise ValueError("ReachEnv: max_episode_steps and substeps must be at least 1")
        self.dof = int(dof)
        self.link_length = float(link_length)
        self.max_episode_steps = int(max_episode_steps)
        self.substeps = int(substeps)
        self.max_joint_speed = float(max_joint_speed)
        self.tolerance = float(tolerance)
        self.scene = _ps.Scene(timestep=1.0 / (control_rate * substeps), gravity=[0, 0, -9.81])
        self.arm = self._build_arm()
        self._tip_link = self.arm.get_links()[-1]
        self._tip_offset = _ps.Pose([self.link_length, 0, 0])
        # the state every episode starts from (the solver's warm start included)
        self._initial_state = self.scene.pack()
        n = 6 + 3 * self.dof
        self.action_space = Box(-1.0, 1.0, (self.dof,), np.float32)
        self.observation_space = Box(-np.inf, np.inf, (n,), np.float32)
        self._np_random = np.random.default_rng()
        self._target = np.zeros(2)
        self._steps = 0
        self._started = False

    def _build_arm(self):
        ab = self.scene.create_articulation_builder()
        ab.set_name("reach_arm")
        base = ab.create_link_builder()
        base.set_name("base").set_mass_and_inertia(1.0, _ps.Pose(), np.full(3, 1e-2))
        parent, pose_in_parent = base, _X_TO_Z
        half = self.link_length / 2
        # a rod of 0.2 kg along x: inertia m l^2 / 12 about y and z
        rod = 0.2 * self.link_length ** 2 / 12
        inertia = np.array([1e-5, rod, rod])
        for i in range(self.dof):
            link = ab.create_link_builder(parent)
            link.set_name(f"link{i + 1}").set_joint_name(f"joint{i + 1}")
            link.set_joint_properties("continuous", [-np.inf, np.inf], pose_in_parent, _X_TO_Z)
            link.set_mass_and_inertia(0.2, _ps.Pose([half, 0, 0]), inertia)
            link.add_capsule_visual(_ps.Pose([half, 0, 0]), radius=0.02, half_length=half,
                                    color=[0.2, 0.4, 0.8, 1])
            parent = link
            pose_in_parent = _ps.Pose([self.link_length, 0, 0], _X_TO_Z.q)
        arm = ab.build(fix_root_link=True)
        for j in arm.get_active_joints():
            j.set_drive_property(0.0, 5.0, 100.0)  # a pure velocity drive
        return arm

    # --- Gymnasium API ---------------------------------------------------------------------

    @property
    def np_random(self) -> np.random.Generator:
        """The generator that draws each episode's start and target; ``reset(seed=...)``
        reseeds it."""
        return self._np_random

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Starts an episode: random joint angles at rest and a random target (the same for
        the same ``seed``; ``options`` is accepted and ignored). Returns (obs, info)."""
        if seed is not None:
            self._np_random = np.random.default_rng(seed)
            self.action_space.seed(seed)
        rng = self._np_random
        q = rng.uniform(-np.pi, np.pi, self.dof)
        if self.dof == 1:
            angle = rng.uniform(-np.pi, np.pi)
            radius = self.link_length
        else:
            angle = rng.uniform(-np.pi, np.pi)
            reach = 2 * self.link_length
            radius = np.sqrt(rng.uniform((0.25 * reach) ** 2, (0.95 * reach) ** 2))
        self._target = radius * np.array([np.cos(angle), np.sin(angle)])
        self.scene.unpack(self._initial_state)
        self.arm.set_qpos(q)
        self.arm.set_qvel(np.zeros(self.dof))
        self.arm.set_drive_velocity_target(np.zeros(self.dof))
        self._steps = 0
        self._started = True
        tip = self.tip_position()
        return self._observation(tip), self._info(tip)

    def step(self, action):
        """Applies the joint velocity targets for one control period; returns (obs, reward,
        terminated, truncated, info). Raises ``RuntimeError`` before ``reset`` and
        ``ValueError`` for a wrong shape or a non-finite action."""
        if not self._started:
            raise RuntimeError("step called before reset")
        a = np.asarray(action, dtype=np.float64)
        if a.shape != (self.dof,):
            raise ValueError(f"action must have shape ({self.dof},), got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError("action holds NaN or infinite values")
        self.arm.set_drive_velocity_target(np.clip(a, -1.0, 1.0) * self.max_joint_speed)
        self.scene.step(self.substeps)
        self._steps += 1
        tip = self.tip_position()
        distance = float(np.linalg.norm(self._target - tip))
        terminated = distance < self.tolerance
        truncated = not terminated and self._steps >= self.max_episode_steps
        return self._observation(tip), -distance, terminated, truncated, self._info(tip)

    def close(self):
        """Nothing to free (the scene goes with the object)."""

    # --- helpers -----------------------------------------------------------------------------

    @property
    def target(self) -> np.ndarray:
        """The episode's target (2,), metres in the base frame."""
        return self._target.copy()

    def tip_position(self) -> np.ndarray:
        """The arm's tip (2,): x, y in metres in the base frame, read from the last link's
        pose in the simulation."""
        return (self._tip_link.get_pose() * self._tip_offset).p[:2]

    def _observation(self, tip):
        q, qd = self.arm.get_qpos(), self.arm.get_qvel()
        return np.concatenate([np.cos(q), np.sin(q), qd / self.max_joint_speed, tip,
                               self._target, self._target - tip]).astype(np.float32)

    def _info(self, tip):
        distance = float(np.linalg.norm(self._target - tip))
        return {"success": distance < self.tolerance, "distance": distance}


def make_reach_vector_env(num_envs: int, **kwargs) -> SyncVectorEnv:
    """``num_envs`` ReachEnv (made with ``kwargs``) as one vector environment with next-step
    autoreset."""
    return SyncVectorEnv([ReachEnv(**kwargs) for _ in range(int(num_envs))])
