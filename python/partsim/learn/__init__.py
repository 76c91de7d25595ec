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

import importlib

# the names below come from modules that need PyTorch; they are imported when first used, so
# that `partsim learn --help` and the protocol's file handling work without it and a missing
# torch is reported by name
_EXPORTS = {
    "ReplayBuffer": "replay", "SAC": "sac", "SACConfig": "sac", "Evaluation": "trainer",
    "SyncVectorEnv": "trainer", "TrainConfig": "trainer", "Trainer": "trainer",
    "evaluate": "trainer",
}

__all__ = ["SAC", "SACConfig", "ReplayBuffer", "Trainer", "TrainConfig", "SyncVectorEnv",
           "Evaluation", "evaluate"]


def __getattr__(name):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'partsim.learn' has no attribute {name!r}")
    try:
        value = getattr(importlib.import_module("." + module, __name__), name)
    except ModuleNotFoundError as e:
        if e.name != "torch":
            raise
        raise ImportError("partsim.learn needs PyTorch: install Debian's python3-torch "
                          "(apt-get install python3-torch)") from e
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
