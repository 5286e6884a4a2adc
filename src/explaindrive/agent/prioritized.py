"""Prioritised experience replay (Schaul et al., 2016, proportional variant).

A transition is sampled with probability ``p_i^alpha / sum_k p_k^alpha``, where its priority
``p_i`` is its last absolute TD error plus :data:`PRIORITY_EPS`; a new transition gets the
largest priority seen so far, so it is sampled at least once soon. Sampling is stratified:
the batch splits the total priority into equal segments and draws one transition in each.
The bias this sampling brings into the updates is undone by importance-sampling weights
``(N * P(i))^-beta``, divided by the batch's largest; ``beta`` is annealed towards 1 over
training (:meth:`~explaindrive.agent.learner.D3QNLearner.priority_beta`).

Rare transitions with large errors (a yellow light seen close ahead, a pedestrian stepping
out) are what uniform replay samples least; the priorities replay them until their values
are learned.

The priorities live in a sum tree: leaf ``i`` holds ``p_i^alpha``, every inner node the sum
of its two children, so drawing a transition and changing a priority cost ``log2(capacity)``
steps, done for a whole batch at once with numpy.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from explaindrive.agent.buffer import ReplayBatch, ReplayBuffer
from explaindrive.env.state import STATE_DIM

PRIORITY_EPS = 0.01
"""Added to every absolute TD error, so that no transition's probability falls to zero."""


class SumTree:
    """Non-negative values of ``capacity`` leaves and the sums of their subtrees.

    The tree is an array of ``2 * leaves`` (``leaves``: the power of two at or above
    ``capacity``): node 1 is the root, node ``k`` has children ``2k`` and ``2k + 1``, and
    leaf ``i`` is node ``leaves + i``.
    """

    def __init__(self, capacity: int) -> None:
        if capacity <= 0:
            raise ValueError(f"sum tree capacity must be > 0, got {capacity}")
        self.capacity = int(capacity)
        self.depth = max(0, (self.capacity - 1).bit_length())
        self.leaves = 1 << self.depth
        self.nodes = np.zeros(2 * self.leaves, dtype=np.float64)

    @property
    def total(self) -> float:
        """The sum of all leaves."""
        return float(self.nodes[1])

    def values(self, indices: NDArray[np.integer]) -> NDArray[np.float64]:
        """The values of leaves ``indices``."""
        return self.nodes[self.leaves + np.asarray(indices, dtype=np.int64)]

    def set(self, indices: NDArray[np.integer], values: NDArray[np.floating]) -> None:
        """Set leaves ``indices`` to ``values`` (the last one wins for a repeated index) and
        recompute the sums above them."""
        nodes = self.leaves + np.asarray(indices, dtype=np.int64).reshape(-1)
        vals = np.broadcast_to(np.asarray(values, dtype=np.float64), nodes.shape)
        if np.any(vals < 0.0) or not np.all(np.isfinite(vals)):
            raise ValueError("sum tree values must be finite and >= 0")
        self.nodes[nodes] = vals
        for _ in range(self.depth):
            nodes = np.unique(nodes // 2)
            self.nodes[nodes] = self.nodes[2 * nodes] + self.nodes[2 * nodes + 1]

    def find(self, targets: NDArray[np.floating]) -> NDArray[np.int64]:
        """The leaf under each target in ``[0, total)``: the first leaf whose running sum of
        values exceeds it."""
        u = np.asarray(targets, dtype=np.float64).copy()
        node = np.ones(u.shape, dtype=np.int64)
        for _ in range(self.depth):
            left = 2 * node
            go_right = u >= self.nodes[left]
            u = np.where(go_right, u - self.nodes[left], u)
            node = left + go_right
        return node - self.leaves


class PrioritizedReplayBuffer(ReplayBuffer):
    """A :class:`ReplayBuffer` sampled in proportion to priorities.

    Args:
        capacity: transitions kept.
        alpha: how much the priorities count (0: uniform sampling).
        state_dim: observation size.
    """

    def __init__(self, capacity: int, alpha: float, state_dim: int = STATE_DIM) -> None:
        super().__init__(capacity, state_dim)
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"priority alpha must be in [0, 1], got {alpha}")
        self.alpha = float(alpha)
        self.tree = SumTree(capacity)
        self.max_priority = 1.0

    def _written(self, slots: NDArray[np.int64]) -> None:
        """New transitions in ``slots`` get the largest priority so far."""
        self.tree.set(slots, self.max_priority**self.alpha)

    def sample(self, batch_size: int, rng: np.random.Generator, beta: float = 1.0) -> ReplayBatch:
        """A stratified sample by priority, with importance-sampling weights for ``beta``.

        Raises:
            ValueError: if the buffer is empty.
        """
        if self.size == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        total = self.tree.total
        bounds = total / batch_size
        targets = (np.arange(batch_size) + rng.random(batch_size)) * bounds
        idx = np.minimum(self.tree.find(np.minimum(targets, np.nextafter(total, 0.0))),
                         self.size - 1)  # fmt: skip
        probs = self.tree.values(idx) / total
        weights = (self.size * np.maximum(probs, 1e-12)) ** -beta
        return self._rows(idx)._replace(
            indices=idx, weights=(weights / weights.max()).astype(np.float32)
        )

    def update_priorities(
        self, indices: NDArray[np.integer], abs_td_errors: NDArray[np.floating]
    ) -> None:
        """Set the priorities of sampled transitions from their new absolute TD errors."""
        priorities = np.abs(np.asarray(abs_td_errors, dtype=np.float64)) + PRIORITY_EPS
        self.max_priority = max(self.max_priority, float(priorities.max(initial=0.0)))
        self.tree.set(indices, priorities**self.alpha)

    def state_dict(self) -> dict[str, NDArray[np.generic]]:
        """:meth:`ReplayBuffer.state_dict` with the priorities of the filled part."""
        state = super().state_dict()
        state["priorities"] = self.tree.values(np.arange(self.size))
        state["max_priority"] = np.array(self.max_priority, dtype=np.float64)
        return state

    def load_state_dict(self, state: dict[str, NDArray[np.generic]]) -> None:
        """Restore :meth:`state_dict`; a buffer saved without priorities (uniform replay)
        gets the largest priority for every transition.

        Raises:
            ValueError: if the saved buffer does not fit this one.
        """
        super().load_state_dict(state)
        if "priorities" in state:
            self.max_priority = float(state["max_priority"])
            self.tree.set(np.arange(self.size), np.asarray(state["priorities"], np.float64))
        else:
            self.tree.set(np.arange(self.size), self.max_priority**self.alpha)
