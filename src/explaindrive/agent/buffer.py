"""Preallocated numpy ring buffer of transitions.

A transition may span n steps (n-step returns): ``reward`` is then the discounted sum of
the n rewards, ``next_obs`` the state n steps later and ``discount`` gamma^n (0 is never
stored: a terminal transition keeps its ``terminated`` flag). ``mask`` and ``next_mask`` mark
the safe actions of ``obs`` and ``next_obs`` (:func:`explaindrive.agent.shield.training_mask`):
learning pushes the others down in ``obs`` and takes the double-DQN argmax among them in
``next_obs``. They serve learning only and are never given to the network.

Memory per transition: ``obs`` and ``next_obs`` as float32 (2 x 8 x 4 = 64 B), the action as
int8 (1 B), the reward and the discount as float32 (8 B), the termination flag as bool
(1 B) and the two masks as 7 bools each (14 B): 88 B. The paper's 5M transitions therefore
take 440 MB (:func:`replay_nbytes`). ``next_obs`` is kept in
its own array rather than recovered from the next slot because transitions of several
parallel envs are interleaved and an episode's last ``next_obs`` is never a stored ``obs``.
The arrays are allocated with ``np.zeros`` so untouched pages cost no resident memory.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from explaindrive.env.actions import N_ACTIONS
from explaindrive.env.state import STATE_DIM


def replay_nbytes(capacity: int, state_dim: int = STATE_DIM) -> int:
    """Bytes held by a :class:`ReplayBuffer` of ``capacity`` transitions."""
    return capacity * (2 * state_dim * 4 + 1 + 4 + 4 + 1 + 2 * N_ACTIONS)


class Transition(NamedTuple):
    """One n-step transition, as a rollout worker ships it."""

    obs: NDArray[np.float32]
    action: int
    reward: float  # the discounted n-step return
    next_obs: NDArray[np.float32]
    terminated: bool
    discount: float  # gamma^n
    mask: NDArray[np.bool_]  # the safe actions of obs
    next_mask: NDArray[np.bool_]  # the safe actions of next_obs


class ReplayBatch(NamedTuple):
    """A sampled minibatch (numpy arrays, first axis = batch)."""

    obs: NDArray[np.float32]
    actions: NDArray[np.int64]
    rewards: NDArray[np.float32]
    next_obs: NDArray[np.float32]
    terminated: NDArray[np.bool_]
    discount: NDArray[np.float32]
    mask: NDArray[np.bool_]
    next_mask: NDArray[np.bool_]
    indices: NDArray[np.int64] | None = None
    """The rows' slots in the buffer (prioritised replay, to update their priorities)."""
    weights: NDArray[np.float32] | None = None
    """Importance-sampling weights of the rows (prioritised replay); ``None``: all 1."""


_FIELDS = ("obs", "next_obs", "actions", "rewards", "terminated", "discount", "mask", "next_mask")


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
        self.discount = np.zeros(capacity, dtype=np.float32)
        self.mask = np.zeros((capacity, N_ACTIONS), dtype=np.bool_)
        self.next_mask = np.zeros((capacity, N_ACTIONS), dtype=np.bool_)
        self.pos = 0  # next slot to write
        self.size = 0

    def __len__(self) -> int:
        return self.size

    @property
    def nbytes(self) -> int:
        """Bytes of the preallocated arrays."""
        return sum(getattr(self, name).nbytes for name in _FIELDS)

    def add(
        self,
        obs: NDArray[np.floating],
        actions: NDArray[np.integer],
        rewards: NDArray[np.floating],
        next_obs: NDArray[np.floating],
        terminated: NDArray[np.bool_],
        discount: NDArray[np.floating] | float,
        mask: NDArray[np.bool_] | None = None,
        next_mask: NDArray[np.bool_] | None = None,
    ) -> None:
        """Append a batch of ``n`` transitions (first axis), overwriting the oldest ones.

        ``discount`` is gamma^n of each transition; a missing mask allows every action.
        """
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
        self.discount[idx] = np.broadcast_to(np.asarray(discount, dtype=np.float32), (n,))
        for name, value in (("mask", mask), ("next_mask", next_mask)):
            target = getattr(self, name)
            target[idx] = True if value is None else np.asarray(value).reshape(n, N_ACTIONS)
        self.pos = int((self.pos + n) % self.capacity)
        self.size = min(self.size + n, self.capacity)
        self._written(idx)

    def _written(self, slots: NDArray[np.int64]) -> None:
        """Hook for subclasses: transitions were just written to ``slots``."""

    def extend(self, transitions: Sequence[Transition]) -> None:
        """Append ``transitions`` in order (:meth:`add` on their columns)."""
        if not transitions:
            return
        self.add(
            obs=np.asarray([t.obs for t in transitions]),
            actions=np.asarray([t.action for t in transitions]),
            rewards=np.asarray([t.reward for t in transitions]),
            next_obs=np.asarray([t.next_obs for t in transitions]),
            terminated=np.asarray([t.terminated for t in transitions]),
            discount=np.asarray([t.discount for t in transitions]),
            mask=np.asarray([t.mask for t in transitions]),
            next_mask=np.asarray([t.next_mask for t in transitions]),
        )

    def sample(self, batch_size: int, rng: np.random.Generator) -> ReplayBatch:
        """Uniform sample with replacement.

        Raises:
            ValueError: if the buffer is empty.
        """
        if self.size == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        return self._rows(rng.integers(0, self.size, size=batch_size))

    def _rows(self, idx: NDArray[np.integer]) -> ReplayBatch:
        """The transitions in slots ``idx``."""
        return ReplayBatch(
            obs=self.obs[idx],
            actions=self.actions[idx].astype(np.int64),
            rewards=self.rewards[idx],
            next_obs=self.next_obs[idx],
            terminated=self.terminated[idx],
            discount=self.discount[idx],
            mask=self.mask[idx],
            next_mask=self.next_mask[idx],
        )

    def state_dict(self) -> dict[str, NDArray[np.generic]]:
        """The filled part of the buffer and its write position (for checkpoints)."""
        n = self.size
        return {
            **{name: getattr(self, name)[:n] for name in _FIELDS},
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
        missing = [name for name in _FIELDS if name not in state]
        if missing:
            raise ValueError(f"saved replay buffer lacks {', '.join(missing)}")
        for name in _FIELDS:
            getattr(self, name)[:n] = state[name]
        self.size = n
        self.pos = int(state["pos"])
