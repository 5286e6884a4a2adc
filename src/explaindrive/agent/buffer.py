"""Preallocated numpy ring buffer of transitions.

Memory per transition: ``obs`` and ``next_obs`` as float32 (2 x 8 x 4 = 64 B), the action as
int8 (1 B), the reward as float32 (4 B) and the termination flag as bool (1 B): 70 B. The
paper's 5M transitions therefore take 350 MB (:func:`replay_nbytes`). ``next_obs`` is kept in
its own array rather than recovered from the next slot because transitions of several
parallel envs are interleaved and an episode's last ``next_obs`` is never a stored ``obs``.
The arrays are allocated with ``np.zeros`` so untouched pages cost no resident memory.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from explaindrive.env.state import STATE_DIM

BYTES_PER_TRANSITION = 2 * STATE_DIM * 4 + 1 + 4 + 1


def replay_nbytes(capacity: int, state_dim: int = STATE_DIM) -> int:
    """Bytes held by a :class:`ReplayBuffer` of ``capacity`` transitions."""
    return capacity * (2 * state_dim * 4 + 1 + 4 + 1)


class ReplayBatch(NamedTuple):
    """A sampled minibatch (numpy arrays, first axis = batch)."""

    obs: NDArray[np.float32]
    actions: NDArray[np.int64]
    rewards: NDArray[np.float32]
    next_obs: NDArray[np.float32]
    terminated: NDArray[np.bool_]


class ReplayBuffer:
    """Fixed-capacity FIFO of transitions with uniform sampling."""

    def __init__(self, capacity: int, state_dim: int = STATE_DIM) -> None:
        if capacity <= 0:
            raise ValueError(f"replay capacity must be > 0, got {capacity}")
        self.capacity = int(capacity)
        self.state_dim = int(state_dim)
        self.obs = np.zeros((capacity, state_dim), dtype=np.float32)
        self.next_obs = np.zeros((capacity, state_dim), dtype=np.float32)
        self.actions = np.zeros(capacity, dtype=np.int8)
        self.rewards = np.zeros(capacity, dtype=np.float32)
        self.terminated = np.zeros(capacity, dtype=np.bool_)
        self.pos = 0  # next slot to write
        self.size = 0

    def __len__(self) -> int:
        return self.size

    @property
    def nbytes(self) -> int:
        """Bytes of the preallocated arrays."""
        arrays = (self.obs, self.next_obs, self.actions, self.rewards, self.terminated)
        return sum(a.nbytes for a in arrays)

    def add(
        self,
        obs: NDArray[np.floating],
        actions: NDArray[np.integer],
        rewards: NDArray[np.floating],
        next_obs: NDArray[np.floating],
        terminated: NDArray[np.bool_],
    ) -> None:
        """Append a batch of ``n`` transitions (first axis), overwriting the oldest ones."""
        obs = np.asarray(obs, dtype=np.float32).reshape(-1, self.state_dim)
        n = obs.shape[0]
        if n > self.capacity:
            raise ValueError(f"cannot add {n} transitions to a buffer of capacity {self.capacity}")
        idx = (self.pos + np.arange(n)) % self.capacity
        self.obs[idx] = obs
        self.next_obs[idx] = np.asarray(next_obs, dtype=np.float32).reshape(n, self.state_dim)
        self.actions[idx] = np.asarray(actions).reshape(n)
        self.rewards[idx] = np.asarray(rewards, dtype=np.float32).reshape(n)
        self.terminated[idx] = np.asarray(terminated, dtype=np.bool_).reshape(n)
        self.pos = int((self.pos + n) % self.capacity)
        self.size = min(self.size + n, self.capacity)

    def sample(self, batch_size: int, rng: np.random.Generator) -> ReplayBatch:
        """Uniform sample with replacement.

        Raises:
            ValueError: if the buffer is empty.
        """
        if self.size == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        idx = rng.integers(0, self.size, size=batch_size)
        return ReplayBatch(
            obs=self.obs[idx],
            actions=self.actions[idx].astype(np.int64),
            rewards=self.rewards[idx],
            next_obs=self.next_obs[idx],
            terminated=self.terminated[idx],
        )

    def state_dict(self) -> dict[str, NDArray[np.generic]]:
        """The filled part of the buffer and its write position (for checkpoints)."""
        n = self.size
        return {
            "obs": self.obs[:n],
            "next_obs": self.next_obs[:n],
            "actions": self.actions[:n],
            "rewards": self.rewards[:n],
            "terminated": self.terminated[:n],
            "pos": np.array(self.pos, dtype=np.int64),
            "capacity": np.array(self.capacity, dtype=np.int64),
        }

    def load_state_dict(self, state: dict[str, NDArray[np.generic]]) -> None:
        """Restore what :meth:`state_dict` returned.

        Raises:
            ValueError: if the saved buffer does not fit this one.
        """
        n = int(state["obs"].shape[0])
        capacity = int(state["capacity"])
        if capacity != self.capacity or state["obs"].shape[1:] != (self.state_dim,):
            raise ValueError(
                f"saved replay buffer (capacity {capacity}, state {state['obs'].shape[1:]}) does "
                f"not match this one (capacity {self.capacity}, state ({self.state_dim},))"
            )
        self.obs[:n] = state["obs"]
        self.next_obs[:n] = state["next_obs"]
        self.actions[:n] = state["actions"]
        self.rewards[:n] = state["rewards"]
        self.terminated[:n] = state["terminated"]
        self.size = n
        self.pos = int(state["pos"])
