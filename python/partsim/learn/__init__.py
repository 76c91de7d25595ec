"""partsim.learn: learning-based manipulation, the SAPIEN paper's Soft Actor-Critic experiment.

Modules:

* ``sac``: the agent (:class:`SAC`, :class:`SACConfig`): twin Q critics with Polyak-averaged
  targets, a squashed Gaussian actor, automatic entropy tuning; an MLP for the ``raw`` and
  ``mobility`` states and a small CNN for ``visual`` observations (RGB-D and the target mask).
* ``replay``: :class:`ReplayBuffer`, a ring of transitions filled by vectorised environments.
* ``trainer``: :class:`Trainer` (the loop for every task: warm-up, updates, progress.csv,
  checkpoints that resume with nothing lost) and :func:`evaluate` (deterministic episodes).
* ``reach``: :class:`ReachEnv`, a one- or two-link arm reaching targets on a partsim scene, the
  task small enough to check that SAC learns.

Example::

    import partsim.envs as envs
    from partsim.learn import SAC, ReplayBuffer, Trainer, TrainConfig, evaluate
    env = envs.VectorOpenCabinetEnv(4, task="drawer", obs_mode="mobility")
    agent = SAC(env.single_observation_space, env.single_action_space, seed=0)
    buffer = ReplayBuffer(1_000_000, env.single_observation_space, agent.action_dim, seed=0)
    Trainer(env, agent, buffer, "runs/drawer", TrainConfig(total_steps=100_000)).train()
"""

from .replay import ReplayBuffer
from .sac import SAC, SACConfig
from .trainer import Evaluation, SyncVectorEnv, TrainConfig, Trainer, evaluate

__all__ = ["SAC", "SACConfig", "ReplayBuffer", "Trainer", "TrainConfig", "SyncVectorEnv",
           "Evaluation", "evaluate"]
