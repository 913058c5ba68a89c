"""A fixed-size replay memory of transitions (s, a, r, s', done) in NumPy (IDL Table 1: 10,000).

Sampling uses its own seeded :class:`numpy.random.Generator`, so a run is reproducible and a
checkpoint (:meth:`ReplayBuffer.state`, :meth:`ReplayBuffer.load_state`) restores it exactly.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError

__all__ = ["ReplayBuffer"]

F32 = npt.NDArray[np.float32]
_FIELDS = ("obs", "actions", "rewards", "next_obs", "dones")


class ReplayBuffer:
    """Ring buffer of ``capacity`` transitions; the oldest are overwritten first.

    Examples
    --------
    >>> buf = ReplayBuffer(4, obs_dim=3, act_dim=1, seed=0)
    >>> for i in range(6):
    ...     buf.add(np.full((1, 3), i), np.zeros((1, 1)), np.array([-i]), np.zeros((1, 3)),
    ...             np.array([False]))
    >>> len(buf), sorted(buf.rewards[:, 0].tolist())
    (4, [-5.0, -4.0, -3.0, -2.0])
    >>> buf.sample(2)["obs"].shape
    (2, 3)
    """

    def __init__(self, capacity: int, *, obs_dim: int, act_dim: int, seed: int) -> None:
        if capacity < 1:
            raise StringStabError(f"replay capacity must be >= 1; got {capacity}")
        self.capacity = int(capacity)
        self.obs = np.zeros((self.capacity, obs_dim), dtype=np.float32)
        self.actions = np.zeros((self.capacity, act_dim), dtype=np.float32)
        self.rewards = np.zeros((self.capacity, 1), dtype=np.float32)
        self.next_obs = np.zeros((self.capacity, obs_dim), dtype=np.float32)
        self.dones = np.zeros((self.capacity, 1), dtype=np.float32)
        self.pos = 0
        self.size = 0
        self.rng = np.random.default_rng(seed)

    def __len__(self) -> int:
        return self.size

    def add(self, obs: npt.ArrayLike, actions: npt.ArrayLike, rewards: npt.ArrayLike,
            next_obs: npt.ArrayLike, dones: npt.ArrayLike) -> None:
        """Append a batch of transitions (leading axis: environments).

        Parameters
        ----------
        obs : array_like (n, obs_dim)
            States s.
        actions : array_like (n, act_dim)
            Actions a (environment units).
        rewards : array_like (n,)
            Rewards r.
        next_obs : array_like (n, obs_dim)
            Next states s' (for an episode that ended, its final state).
        dones : array_like (n,)
            1 where s' is terminal (the target then uses ``terminal_value``), else 0.
        """
        o = np.asarray(obs, dtype=np.float32)
        n = o.shape[0]
        a = np.asarray(actions, dtype=np.float32).reshape(n, -1)
        r = np.asarray(rewards, dtype=np.float32).reshape(n)
        o2 = np.asarray(next_obs, dtype=np.float32)
        d = np.asarray(dones, dtype=np.float32).reshape(n)
        # a batch larger than the buffer: only its newest ``capacity`` transitions remain
        # (written once each, as if the batch had been added one transition at a time)
        keep = slice(max(0, n - self.capacity), n)
        m = n - keep.start
        idx = (self.pos + keep.start + np.arange(m)) % self.capacity
        self.obs[idx] = o[keep]
        self.actions[idx] = a[keep]
        self.rewards[idx, 0] = r[keep]
        self.next_obs[idx] = o2[keep]
        self.dones[idx, 0] = d[keep]
        self.pos = int((self.pos + n) % self.capacity)
        self.size = int(min(self.size + n, self.capacity))

    def sample(self, batch_size: int) -> dict[str, F32]:
        """A uniform minibatch (with replacement), as float32 arrays.

        Parameters
        ----------
        batch_size : int
            Transitions to draw.

        Returns
        -------
        dict of str to ndarray
            ``obs``, ``actions``, ``rewards`` (batch_size, 1), ``next_obs``, ``dones``
            (batch_size, 1).

        Raises
        ------
        StringStabError
            If the buffer is empty.
        """
        if self.size == 0:
            raise StringStabError("cannot sample from an empty replay buffer")
        idx = self.rng.integers(0, self.size, size=batch_size)
        return {f: getattr(self, f)[idx] for f in _FIELDS}

    # -- checkpoints ----------------------------------------------------------------------
    def arrays(self) -> dict[str, F32]:
        """The stored transitions (the filled part), for a checkpoint."""
        return {f: np.ascontiguousarray(getattr(self, f)[: self.size]) for f in _FIELDS}

    def state(self) -> dict[str, Any]:
        """Counters and the sampler's RNG state (JSON-ready)."""
        return {"capacity": self.capacity, "pos": self.pos, "size": self.size,
                "rng": self.rng.bit_generator.state}

    def load_state(self, state: dict[str, Any], arrays: dict[str, Any]) -> None:
        """Restore from :meth:`state` and :meth:`arrays` (shapes are checked).

        Parameters
        ----------
        state : dict
            :meth:`state` output: ``capacity``, ``pos``, ``size``, ``rng``.
        arrays : dict of str to ndarray
            :meth:`arrays` output: the stored transitions.

        Raises
        ------
        StringStabError
            If a key or an array is missing, the capacity differs or an array has another shape.
        """
        missing = [k for k in ("capacity", "pos", "size", "rng") if k not in state]
        missing += [f for f in _FIELDS if f not in arrays]
        if missing:
            raise StringStabError(f"replay buffer: expected {', '.join(missing)} in the checkpoint; "
                                  f"found state keys {sorted(state)} and arrays {sorted(arrays)}")
        size = int(state["size"])
        if int(state["capacity"]) != self.capacity or not 0 <= size <= self.capacity:
            raise StringStabError(
                f"replay buffer: expected capacity {self.capacity}; found {state['capacity']} "
                f"with {size} transitions")
        for f in _FIELDS:
            a = np.asarray(arrays[f])
            want = (size, getattr(self, f).shape[1])
            if a.shape != want:
                raise StringStabError(f"replay buffer {f}: expected shape {want}; found {a.shape}")
            getattr(self, f)[:size] = a
        self.pos, self.size = int(state["pos"]) % self.capacity, size
        self.rng.bit_generator.state = state["rng"]
