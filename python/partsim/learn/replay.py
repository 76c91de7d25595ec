"""A replay buffer of transitions for off-policy learning (SAC), filled by vectorised
environments: a ring of fixed capacity in numpy arrays, one array per field (and per key of
dict observations, each in the observation's own dtype: images stay uint8)."""

from __future__ import annotations

import json
import os

import numpy as np

__all__ = ["ReplayBuffer"]

FIELDS = ("obs", "action", "reward", "next_obs", "terminated")


def _is_dict_space(space) -> bool:
    return hasattr(space, "spaces")


class ReplayBuffer:
    """Transitions (obs, action, reward, next_obs, terminated) in a ring of ``capacity`` slots:
    once full, each new transition overwrites the oldest.

    ``observation_space``: a Box, or a Dict of Boxes (partsim.envs or Gymnasium spaces) whose
    shapes and dtypes the stored arrays take; ``action_dim``: the size of an action (float32).
    ``seed`` seeds the buffer's own ``numpy.random.Generator`` that ``sample`` draws from.
    Observations are stored twice (obs and next_obs): ``nbytes`` tells the memory it takes.
    """

    def __init__(self, capacity: int, observation_space, action_dim: int, seed: int = 0):
        if capacity < 1:
            raise ValueError(f"ReplayBuffer: capacity must be at least 1, got {capacity}")
        self.capacity = int(capacity)
        self.action_dim = int(action_dim)
        self.is_dict = _is_dict_space(observation_space)
        if self.is_dict:
            self._obs_specs = {k: (tuple(s.shape), np.dtype(s.dtype))
                               for k, s in observation_space.spaces.items()}
        else:
            self._obs_specs = {None: (tuple(observation_space.shape),
                                      np.dtype(observation_space.dtype))}
        self._data = {}
        for prefix in ("obs", "next_obs"):
            for k, (shape, dtype) in self._obs_specs.items():
                self._data[_key(prefix, k)] = np.zeros((self.capacity,) + shape, dtype)
        self._data["action"] = np.zeros((self.capacity, self.action_dim), np.float32)
        self._data["reward"] = np.zeros(self.capacity, np.float32)
        self._data["terminated"] = np.zeros(self.capacity, np.bool_)
        self.pos = 0
        self.size = 0
        self.rng = np.random.default_rng(seed)

    def __len__(self) -> int:
        return self.size

    @property
    def nbytes(self) -> int:
        """Bytes held by the arrays (the whole capacity)."""
        return sum(a.nbytes for a in self._data.values())

    def add(self, obs, action, reward, next_obs, terminated) -> None:
        """Stores n transitions at once, one per row: ``obs`` and ``next_obs`` (n, ...) arrays
        (dicts of them for dict observations), ``action`` (n, action_dim), ``reward`` and
        ``terminated`` (n,). Rows are written in order at the ring's position; more rows than
        the capacity keep the last ``capacity``."""
        action = np.asarray(action, np.float32).reshape(-1, self.action_dim)
        n = action.shape[0]
        rows = {"action": action,
                "reward": np.asarray(reward, np.float32).reshape(n),
                "terminated": np.asarray(terminated, np.bool_).reshape(n)}
        for prefix, o in (("obs", obs), ("next_obs", next_obs)):
            for k, (shape, dtype) in self._obs_specs.items():
                a = np.asarray(o[k] if k is not None else o)
                if a.shape != (n,) + shape:
                    name = prefix if k is None else f"{prefix}[{k!r}]"
                    raise ValueError(f"ReplayBuffer.add: {name} has shape {a.shape}, expected "
                                     f"{(n,) + shape}")
                rows[_key(prefix, k)] = a
        if n == 0:
            return
        if n > self.capacity:
            rows = {k: v[n - self.capacity:] for k, v in rows.items()}
            self.pos = (self.pos + n - self.capacity) % self.capacity
            n = self.capacity
        idx = (self.pos + np.arange(n)) % self.capacity
        for k, v in rows.items():
            self._data[k][idx] = v  # casts to the stored dtype
        self.pos = int((self.pos + n) % self.capacity)
        self.size = int(min(self.size + n, self.capacity))

    def sample(self, batch_size: int) -> dict:
        """``batch_size`` transitions drawn uniformly with replacement from the stored ones:
        a dict of ``obs``, ``action``, ``reward``, ``next_obs`` and ``terminated`` arrays
        (observations as dicts for dict spaces). Raises ``ValueError`` when empty."""
        if self.size == 0:
            raise ValueError("ReplayBuffer.sample: the buffer is empty")
        idx = self.rng.integers(0, self.size, size=int(batch_size))
        return self.get(idx)

    def get(self, idx) -> dict:
        """The transitions at slots ``idx`` (an index array), as ``sample`` returns them."""
        out = {k: self._data[k][idx] for k in ("action", "reward", "terminated")}
        for prefix in ("obs", "next_obs"):
            if self.is_dict:
                out[prefix] = {k: self._data[_key(prefix, k)][idx] for k in self._obs_specs}
            else:
                out[prefix] = self._data[prefix][idx]
        return out

    # --- checkpoints ------------------------------------------------------------------------

    def state_dict(self) -> dict:
        """The stored transitions (the filled slots' arrays, not copies), the position, the
        size and the generator's state."""
        return {
            "arrays": {k: v[:self.size] for k, v in self._data.items()},
            "pos": self.pos,
            "size": self.size,
            "capacity": self.capacity,
            "rng": self.rng.bit_generator.state,
        }

    def load_state_dict(self, state: dict) -> None:
        """Restores ``state_dict()``'s output (from a buffer of the same capacity and
        spaces; others raise ``ValueError``)."""
        if int(state["capacity"]) != self.capacity:
            raise ValueError(f"ReplayBuffer.load_state_dict: capacity {state['capacity']} "
                             f"in the state, {self.capacity} here")
        size = int(state["size"])
        arrays = state["arrays"]
        if set(arrays) != set(self._data):
            raise ValueError(f"ReplayBuffer.load_state_dict: fields {sorted(arrays)} in the "
                             f"state, {sorted(self._data)} here")
        for k, a in arrays.items():
            if a.shape[1:] != self._data[k].shape[1:] or len(a) != size:
                raise ValueError(f"ReplayBuffer.load_state_dict: {k} has shape {a.shape}, "
                                 f"expected {(size,) + self._data[k].shape[1:]}")
            self._data[k][:size] = a
            self._data[k][size:] = 0
        self.pos, self.size = int(state["pos"]), size
        self.rng.bit_generator.state = state["rng"]

    def save(self, path) -> None:
        """Writes the buffer with ``numpy.savez`` (uncompressed: the filled slots' arrays,
        position, size, capacity and the generator's state as JSON) to ``path``, a file name
        (used as given: no ``.npz`` is appended) or a binary file object."""
        state = self.state_dict()
        meta = {k: state[k] for k in ("pos", "size", "capacity", "rng")}
        if hasattr(path, "write"):
            np.savez(path, _meta=np.array(json.dumps(meta)), **state["arrays"])
            return
        with open(path, "wb") as f:
            np.savez(f, _meta=np.array(json.dumps(meta)), **state["arrays"])

    def load(self, path) -> None:
        """Reads a file written by ``save`` into this buffer."""
        with np.load(os.fspath(path), allow_pickle=False) as z:
            meta = json.loads(str(z["_meta"]))
            arrays = {k: z[k] for k in z.files if k != "_meta"}
        self.load_state_dict(dict(meta, arrays=arrays))


def _key(prefix, k):
    """The array name of an observation field: 'obs' or 'obs.rgb'."""
    return prefix if k is None else f"{prefix}.{k}"
