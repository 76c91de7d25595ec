"""The reference learner: Stable-Baselines3's SAC (pinned in requirements.lock) learns the small
reaching task partsim's SAC learns (test_learn_sac.py's test_sac_learns_to_reach), on the same
environment and budget, against the same random policy; the comparison on the real tasks is
bench/sb3_compare.py."""

import numpy as np

from conftest import require

require("torch", "python3-torch (scripts/setup.sh)")
sb3 = require("stable_baselines3", "stable-baselines3 (requirements.lock)")

from partsim.learn.reach import ReachEnv  # noqa: E402
from partsim.learn.trainer import evaluate  # noqa: E402


def test_sb3_sac_learns_to_reach():
    """5000 steps of one environment, an update per step, otherwise the hyper-parameters of
    partsim's reach test (about 50 s on one core)."""
    import torch

    torch.set_num_threads(1)
    model = sb3.SAC("MlpPolicy", ReachEnv(), learning_rate=1e-3, buffer_size=10000,
                    learning_starts=300, batch_size=64, tau=0.01, gamma=0.95,
                    policy_kwargs={"net_arch": [64, 64]}, seed=0, device="cpu")
    model.learn(5000)
    learned = evaluate(ReachEnv(), None, 30, seed=1000,
                       policy=lambda obs: model.predict(obs, deterministic=True)[0])
    rng = np.random.default_rng(0)
    random = evaluate(ReachEnv(), None, 30, seed=1000,
                      policy=lambda obs: rng.uniform(-1, 1, (len(obs), 2)))
    # partsim's reach test's bound on the return; SB3 gets closer to every target but, on one
    # environment and this budget, inside the 5 cm tolerance less often than partsim's SAC
    assert random.mean_return < -20
    assert learned.mean_return > 0.5 * random.mean_return + 3, (learned.mean_return,
                                                                random.mean_return)
    assert learned.success_rate > random.success_rate, (learned.success_rate,
                                                        random.success_rate)
