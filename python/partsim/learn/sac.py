"""Soft Actor-Critic (Haarnoja et al. 2018, "Soft Actor-Critic Algorithms and Applications") in
PyTorch: a squashed Gaussian actor, twin Q critics with Polyak-averaged targets and automatic
entropy tuning.

Observations are either vectors (the ``raw`` and ``mobility`` states of partsim.envs: an
:class:`MLP` on the vector) or the ``visual`` dict (``rgb`` (h, w, 3) uint8, ``depth`` (h, w)
float32 metres, ``mask`` (h, w) uint8, ``state`` (s,) float32), which :class:`ConvEncoder` turns
into features: a 5-channel image (rgb / 255, depth, mask) through a few convolutions, then
concatenated with the state.

Encoder sharing: with vector observations there is nothing to share (the actor and each critic
are MLPs on the vector). With images, one ConvEncoder belongs to the critic and serves both Q
heads; the actor reads its features detached, so the encoder learns from the critic's loss only
(as SAC-AE and DrQ do); the target critic holds its own Polyak-averaged copy of the encoder.

The losses are functions of tensors (:func:`critic_target`, :func:`critic_loss`,
:func:`policy_loss`, :func:`alpha_loss`, :func:`squashed_gaussian`, :func:`polyak_update`) so
that they can be checked on hand-made numbers; :meth:`SAC.update` strings them together.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from typing import Sequence

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

__all__ = [
    "SACConfig", "SAC", "MLP", "VectorEncoder", "ConvEncoder", "Actor", "Critic",
    "make_encoder", "squashed_gaussian", "critic_target", "critic_loss", "policy_loss",
    "alpha_loss", "polyak_update", "LOG_STD_MIN", "LOG_STD_MAX",
]

# bounds of the actor's log standard deviation (Spinning Up and Stable-Baselines3 use these)
LOG_STD_MIN = -20.0
LOG_STD_MAX = 2.0
# keys of a visual observation; depth beyond this many metres reads as this far
IMAGE_KEYS = ("rgb", "depth", "mask")
MAX_DEPTH = 10.0


@dataclasses.dataclass
class SACConfig:
    """Hyper-parameters of :class:`SAC` (defaults: Haarnoja et al. 2018's, Table 1).

    ``hidden_sizes``: widths of the hidden layers of the actor and of each Q network.
    ``lr``: Adam's learning rate of the actor, the critics and the temperature.
    ``gamma``: discount; ``tau``: Polyak coefficient of the target critics (target <- (1 - tau)
    target + tau critic, every ``target_update_interval`` updates); ``batch_size``: transitions
    per update (the trainer samples them). ``init_alpha``: initial temperature; ``auto_alpha``:
    tune log(alpha) towards ``target_entropy`` (None: -action_dim). ``conv_channels``,
    ``conv_strides`` and ``feature_dim``: the ConvEncoder of visual observations (3x3 kernels;
    features are a linear layer, LayerNorm and tanh of the last map, then the state).
    """

    hidden_sizes: tuple = (256, 256)
    lr: float = 3e-4
    gamma: float = 0.99
    tau: float = 0.005
    batch_size: int = 256
    init_alpha: float = 1.0
    auto_alpha: bool = True
    target_entropy: float | None = None
    target_update_interval: int = 1
    conv_channels: tuple = (32, 32, 32)
    conv_strides: tuple = (2, 2, 1)
    feature_dim: int = 50

    def to_dict(self) -> dict:
        """The settings as a plain dict (JSON-ready; tuples become lists)."""
        return {k: list(v) if isinstance(v, tuple) else v
                for k, v in dataclasses.asdict(self).items()}

    @classmethod
    def from_dict(cls, d: dict) -> "SACConfig":
        """The config of ``to_dict``'s output (unknown keys raise ``TypeError``)."""
        d = dict(d)
        for k in ("hidden_sizes", "conv_channels", "conv_strides"):
            if k in d:
                d[k] = tuple(d[k])
        return cls(**d)


# --- networks --------------------------------------------------------------------------------


class MLP(nn.Sequential):
    """Linear layers with ReLU between them: ``in_dim -> hidden_sizes... -> out_dim``."""

    def __init__(self, in_dim: int, hidden_sizes: Sequence[int], out_dim: int):
        layers, d = [], int(in_dim)
        for h in hidden_sizes:
            layers += [nn.Linear(d, int(h)), nn.ReLU()]
            d = int(h)
        layers.append(nn.Linear(d, int(out_dim)))
        super().__init__(*layers)


class VectorEncoder(nn.Module):
    """Features of a vector observation: the vector itself as float32 (``out_dim`` = its size);
    the MLPs of the actor and the critics do the encoding."""

    def __init__(self, obs_dim: int):
        super().__init__()
        self.out_dim = int(obs_dim)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        """(n, obs_dim) features of (n, obs_dim) observations."""
        return obs.float().reshape(obs.shape[0], -1)


class ConvEncoder(nn.Module):
    """Features of a visual observation dict (``rgb`` (n, h, w, 3) uint8, ``depth`` (n, h, w)
    metres, ``mask`` (n, h, w) uint8, ``state`` (n, s)): the image (rgb / 255, depth clipped to
    [0, 10] m, mask) through 3x3 convolutions with ReLU, a linear layer to ``feature_dim``,
    LayerNorm and tanh, then the state appended: ``out_dim = feature_dim + s``."""

    def __init__(self, height: int, width: int, state_dim: int, channels=(32, 32, 32),
                 strides=(2, 2, 1), feature_dim: int = 50):
        super().__init__()
        if len(channels) != len(strides) or not channels:
            raise ValueError("ConvEncoder: channels and strides must have the same, non-zero "
                             f"length (got {len(channels)} and {len(strides)})")
        convs, c = [], 5
        for out, stride in zip(channels, strides):
            convs += [nn.Conv2d(c, int(out), 3, stride=int(stride)), nn.ReLU()]
            c = int(out)
        self.convs = nn.Sequential(*convs)
        with torch.no_grad():
            flat = self.convs(torch.zeros(1, 5, int(height), int(width))).numel()
        self.head = nn.Sequential(nn.Linear(flat, int(feature_dim)), nn.LayerNorm(feature_dim),
                                  nn.Tanh())
        self.state_dim = int(state_dim)
        self.out_dim = int(feature_dim) + self.state_dim

    def forward(self, obs: dict) -> torch.Tensor:
        """(n, out_dim) features of a batch of visual observations."""
        rgb = obs["rgb"].float().permute(0, 3, 1, 2) / 255.0
        depth = torch.nan_to_num(obs["depth"].float(), nan=0.0, posinf=MAX_DEPTH)
        depth = depth.clamp(0.0, MAX_DEPTH).unsqueeze(1)
        mask = obs["mask"].float().unsqueeze(1)
        x = self.convs(torch.cat([rgb, depth, mask], dim=1))
        x = self.head(x.flatten(1))
        return torch.cat([x, obs["state"].float().reshape(x.shape[0], -1)], dim=1)


def _space_kind(space):
    """'dict' for a visual Dict space, 'vector' for a Box."""
    if hasattr(space, "spaces"):
        missing = {"rgb", "depth", "mask", "state"} - set(space.spaces)
        if missing:
            raise ValueError(f"a dict observation needs the keys rgb, depth, mask and state; "
                             f"missing {sorted(missing)}")
        return "dict"
    return "vector"


def make_encoder(observation_space, config: SACConfig) -> nn.Module:
    """The encoder of one observation space: :class:`VectorEncoder` for a Box,
    :class:`ConvEncoder` for the visual Dict (partsim.envs spaces or Gymnasium's)."""
    if _space_kind(observation_space) == "dict":
        h, w = observation_space.spaces["rgb"].shape[:2]
        s = int(np.prod(observation_space.spaces["state"].shape))
        return ConvEncoder(h, w, s, config.conv_channels, config.conv_strides, config.feature_dim)
    return VectorEncoder(int(np.prod(observation_space.shape)))


class Actor(nn.Module):
    """The policy head: an MLP from features to the mean and log standard deviation of a
    Gaussian over the pre-tanh action (``action_dim`` each)."""

    def __init__(self, feature_dim: int, action_dim: int, hidden_sizes: Sequence[int]):
        super().__init__()
        self.net = MLP(feature_dim, hidden_sizes, 2 * action_dim)
        self.action_dim = int(action_dim)

    def forward(self, features: torch.Tensor):
        """(mean, log_std), each (n, action_dim); log_std clamped to [LOG_STD_MIN,
        LOG_STD_MAX]."""
        mean, log_std = self.net(features).chunk(2, dim=-1)
        return mean, log_std.clamp(LOG_STD_MIN, LOG_STD_MAX)


class Critic(nn.Module):
    """Twin Q networks on (features, action) behind one encoder of the observation."""

    def __init__(self, encoder: nn.Module, action_dim: int, hidden_sizes: Sequence[int]):
        super().__init__()
        self.encoder = encoder
        self.q1 = MLP(encoder.out_dim + action_dim, hidden_sizes, 1)
        self.q2 = MLP(encoder.out_dim + action_dim, hidden_sizes, 1)

    def forward(self, obs, action: torch.Tensor, features: torch.Tensor | None = None):
        """(q1, q2), each (n,), of observations (or their ``features``, when given) and
        actions (n, action_dim)."""
        if features is None:
            features = self.encoder(obs)
        x = torch.cat([features, action], dim=-1)
        return self.q1(x).squeeze(-1), self.q2(x).squeeze(-1)


# --- losses and updates, on tensors ---------------------------------------------------------


def squashed_gaussian(mean: torch.Tensor, log_std: torch.Tensor, noise: torch.Tensor):
    """The action tanh(u), u = mean + exp(log_std) * noise, and its log-density (n,).

    With a = tanh(u), log pi(a) = log N(u; mean, std) - sum_i log(1 - tanh(u_i)^2), and
    log(1 - tanh(u)^2) = 2 (log 2 - u - softplus(-2u)) is computed in that form, which stays
    finite where tanh(u) rounds to +-1.
    """
    std = log_std.exp()
    u = mean + std * noise
    log_normal = -0.5 * noise.pow(2) - log_std - 0.5 * math.log(2.0 * math.pi)
    log_jacobian = 2.0 * (math.log(2.0) - u - F.softplus(-2.0 * u))
    return torch.tanh(u), (log_normal - log_jacobian).sum(dim=-1)


def critic_target(reward: torch.Tensor, terminated: torch.Tensor, next_q1: torch.Tensor,
                  next_q2: torch.Tensor, next_log_prob: torch.Tensor, alpha, gamma: float):
    """The soft Bellman target r + gamma (1 - terminated) (min(Q1', Q2') - alpha log pi(a'|s'))
    (n,); ``terminated`` is 1 where the episode reached a terminal state (not where it was only
    truncated)."""
    next_v = torch.min(next_q1, next_q2) - alpha * next_log_prob
    return reward + gamma * (1.0 - terminated.to(next_v.dtype)) * next_v


def critic_loss(q: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Mean squared error of one Q network against the (fixed) target."""
    return F.mse_loss(q, target.detach())


def policy_loss(log_prob: torch.Tensor, q1: torch.Tensor, q2: torch.Tensor, alpha):
    """The actor's loss mean(alpha log pi(a|s) - min(Q1(s, a), Q2(s, a))), a ~ pi."""
    return (alpha * log_prob - torch.min(q1, q2)).mean()


def alpha_loss(log_alpha: torch.Tensor, log_prob: torch.Tensor, target_entropy: float):
    """The temperature's loss -mean(log_alpha (log pi + target_entropy)): its gradient raises
    alpha while the policy's entropy is below the target and lowers it above."""
    return -(log_alpha * (log_prob.detach() + target_entropy)).mean()


@torch.no_grad()
def polyak_update(target: nn.Module, source: nn.Module, tau: float) -> None:
    """target <- (1 - tau) target + tau source, parameter by parameter (buffers are
    copied)."""
    for t, s in zip(target.parameters(), source.parameters()):
        t.mul_(1.0 - tau).add_(s, alpha=tau)
    for t, s in zip(target.buffers(), source.buffers()):
        t.copy_(s)


# --- the agent --------------------------------------------------------------------------------


class SAC:
    """Soft Actor-Critic agent for one observation space and a Box action space in [-1, 1]
    (``action_space`` a Box or the action size).

    ``seed`` fixes the initial weights (drawn with torch's global generator inside
    ``torch.random.fork_rng``, which leaves it as it was) and the agent's own
    ``torch.Generator`` that draws the actions' noise: the same seed gives the same weights
    and, for the same observations and updates, the same actions. ``device``: a torch device
    (CPU by default).
    """

    def __init__(self, observation_space, action_space, config: SACConfig | None = None,
                 seed: int = 0, device="cpu"):
        self.config = config or SACConfig()
        self.device = torch.device(device)
        self.observation_space = observation_space
        self.obs_kind = _space_kind(observation_space)
        self.action_dim = (int(action_space) if isinstance(action_space, (int, np.integer))
                           else int(np.prod(action_space.shape)))
        self.seed = int(seed)
        cfg = self.config
        self.target_entropy = float(cfg.target_entropy if cfg.target_entropy is not None
                                    else -self.action_dim)
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(self.seed)
            critic_encoder = make_encoder(observation_space, cfg)
            self.critic = Critic(critic_encoder, self.action_dim, cfg.hidden_sizes)
            # the actor reads the critic's encoder, detached
            self.actor = Actor(critic_encoder.out_dim, self.action_dim, cfg.hidden_sizes)
        self.critic.to(self.device)
        self.actor.to(self.device)
        self.critic_target = copy.deepcopy(self.critic)
        for p in self.critic_target.parameters():
            p.requires_grad_(False)
        self.log_alpha = torch.tensor(math.log(cfg.init_alpha), device=self.device,
                                      requires_grad=True)
        self.actor_optimizer = torch.optim.Adam(self.actor.parameters(), lr=cfg.lr)
        self.critic_optimizer = torch.optim.Adam(self.critic.parameters(), lr=cfg.lr)
        self.alpha_optimizer = torch.optim.Adam([self.log_alpha], lr=cfg.lr)
        self.generator = torch.Generator(device=self.device)
        self.generator.manual_seed(self.seed + 1)
        self.updates = 0

    # --- acting -----------------------------------------------------------------------------

    @property
    def alpha(self) -> float:
        """The current temperature exp(log_alpha)."""
        return float(self.log_alpha.detach().exp())

    def to_tensors(self, obs):
        """A batch of observations (numpy arrays or tensors; a dict of them for visual
        observations) as tensors on the agent's device; uint8 images stay uint8 until the
        encoder."""
        if isinstance(obs, dict):
            return {k: self._tensor(v) for k, v in obs.items()}
        return self._tensor(obs).float()

    def _tensor(self, x):
        if isinstance(x, torch.Tensor):
            return x.to(self.device)
        return torch.as_tensor(np.asarray(x), device=self.device)

    def _sample(self, features: torch.Tensor):
        mean, log_std = self.actor(features)
        noise = torch.randn(mean.shape, generator=self.generator, device=self.device)
        return squashed_gaussian(mean, log_std, noise)

    @torch.no_grad()
    def act(self, obs, deterministic: bool = False) -> np.ndarray:
        """Actions (n, action_dim) float32 in [-1, 1] for a batch of n observations (a
        (n, obs_dim) array or a dict of (n, ...) arrays). ``deterministic``: tanh of the mean
        (evaluation); otherwise a sample of the policy."""
        obs = self.to_tensors(obs)
        features = self.critic.encoder(obs)
        if deterministic:
            action = torch.tanh(self.actor(features)[0])
        else:
            action = self._sample(features)[0]
        return action.cpu().numpy().astype(np.float32)

    # --- learning ---------------------------------------------------------------------------

    def update(self, batch: dict) -> dict:
        """One gradient step of the critics, the actor and the temperature, then the target
        critics' Polyak step, on a batch (``obs``, ``action``, ``reward``, ``next_obs``,
        ``terminated``; numpy arrays or tensors, as ReplayBuffer.sample returns). Returns the
        floats q1_loss, q2_loss, policy_loss, alpha_loss, alpha (before this step's change),
        entropy (-mean log pi of the actor's fresh actions) and q_mean (mean Q1 of the
        batch)."""
        cfg = self.config
        obs = self.to_tensors(batch["obs"])
        next_obs = self.to_tensors(batch["next_obs"])
        action = self._tensor(batch["action"]).float()
        reward = self._tensor(batch["reward"]).float().reshape(-1)
        terminated = self._tensor(batch["terminated"]).float().reshape(-1)
        alpha = self.log_alpha.detach().exp()

        # critics: regress both Q on the soft Bellman target
        with torch.no_grad():
            next_features = self.critic_target.encoder(next_obs)
            next_action, next_log_prob = self._sample(self.critic.encoder(next_obs))
            next_q1, next_q2 = self.critic_target(None, next_action, features=next_features)
            target = critic_target(reward, terminated, next_q1, next_q2, next_log_prob, alpha,
                                   cfg.gamma)
        features = self.critic.encoder(obs)
        q1, q2 = self.critic(None, action, features=features)
        loss_q1, loss_q2 = critic_loss(q1, target), critic_loss(q2, target)
        self.critic_optimizer.zero_grad(set_to_none=True)
        (loss_q1 + loss_q2).backward()
        self.critic_optimizer.step()

        # actor: the encoder's features are the critic's, without their gradient
        features = features.detach()
        new_action, log_prob = self._sample(features)
        for p in self.critic.parameters():
            p.requires_grad_(False)
        pq1, pq2 = self.critic(None, new_action, features=features)
        loss_pi = policy_loss(log_prob, pq1, pq2, alpha)
        self.actor_optimizer.zero_grad(set_to_none=True)
        loss_pi.backward()
        self.actor_optimizer.step()
        for p in self.critic.parameters():
            p.requires_grad_(True)

        # temperature
        loss_alpha = alpha_loss(self.log_alpha, log_prob, self.target_entropy)
        if cfg.auto_alpha:
            self.alpha_optimizer.zero_grad(set_to_none=True)
            loss_alpha.backward()
            self.alpha_optimizer.step()

        self.updates += 1
        if self.updates % cfg.target_update_interval == 0:
            polyak_update(self.critic_target, self.critic, cfg.tau)
        return {
            "q1_loss": float(loss_q1), "q2_loss": float(loss_q2), "policy_loss": float(loss_pi),
            "alpha_loss": float(loss_alpha), "alpha": float(alpha),
            "entropy": float(-log_prob.detach().mean()), "q_mean": float(q1.detach().mean()),
        }

    # --- checkpoints ------------------------------------------------------------------------

    def state_dict(self) -> dict:
        """Everything a resumed agent needs to continue bit-identically: the networks, the
        target critics, the three optimizers, log_alpha, the noise generator's state, the
        update counter and the config."""
        return {
            "config": self.config.to_dict(),
            "action_dim": self.action_dim,
            "seed": self.seed,
            "actor": self.actor.state_dict(),
            "critic": self.critic.state_dict(),
            "critic_target": self.critic_target.state_dict(),
            "log_alpha": self.log_alpha.detach().clone(),
            "actor_optimizer": self.actor_optimizer.state_dict(),
            "critic_optimizer": self.critic_optimizer.state_dict(),
            "alpha_optimizer": self.alpha_optimizer.state_dict(),
            "generator": self.generator.get_state(),
            "updates": self.updates,
        }

    def load_state_dict(self, state: dict) -> None:
        """Restores ``state_dict()``'s output into this agent (made with the same observation
        space, action size and config; a different action size raises ``ValueError``)."""
        if int(state["action_dim"]) != self.action_dim:
            raise ValueError(f"load_state_dict: the state is of an agent with "
                             f"{state['action_dim']} actions, this one has {self.action_dim}")
        self.actor.load_state_dict(state["actor"])
        self.critic.load_state_dict(state["critic"])
        self.critic_target.load_state_dict(state["critic_target"])
        with torch.no_grad():
            self.log_alpha.copy_(state["log_alpha"])
        self.actor_optimizer.load_state_dict(state["actor_optimizer"])
        self.critic_optimizer.load_state_dict(state["critic_optimizer"])
        self.alpha_optimizer.load_state_dict(state["alpha_optimizer"])
        self.generator.set_state(state["generator"])
        self.updates = int(state["updates"])
        self.seed = int(state["seed"])

    def save(self, path) -> None:
        """Writes ``state_dict()`` to ``path`` (torch.save)."""
        torch.save(self.state_dict(), path)

    def load(self, path) -> None:
        """Reads a file written by ``save`` into this agent."""
        self.load_state_dict(torch.load(path, map_location=self.device))
