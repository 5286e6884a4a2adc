"""Prioritised replay: the sum tree, sampling in proportion, importance weights, resume."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from explaindrive.agent.config import PASSENGER
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.prioritized import PRIORITY_EPS, PrioritizedReplayBuffer, SumTree
from explaindrive.agent.targets import td_loss


def _fill(buf: PrioritizedReplayBuffer, n: int) -> None:
    ids = np.arange(n, dtype=np.float32)
    obs = np.repeat(ids[:, None], 8, axis=1)
    buf.add(obs, ids.astype(np.int64) % 7, ids, obs + 0.5, np.zeros(n, bool), 0.99)


def test_sum_tree_sums_and_finds_by_hand() -> None:
    tree = SumTree(5)  # 8 leaves, the last three empty
    assert (tree.leaves, tree.depth) == (8, 3)
    tree.set(np.arange(5), np.array([1.0, 2.0, 3.0, 4.0, 5.0]))
    assert tree.total == 15.0
    assert tree.nodes[2:4].tolist() == [10.0, 5.0]  # (1+2+3+4) and 5
    # running sums 1, 3, 6, 10, 15: a target falls to the first leaf whose sum exceeds it
    assert tree.find(np.array([0.0, 0.99, 1.0, 2.5, 5.9, 6.0, 9.99, 14.5])).tolist() == [
        0, 0, 1, 1, 2, 3, 3, 4,
    ]  # fmt: skip
    tree.set(np.array([1, 1]), np.array([7.0, 0.0]))  # the last value for a repeated leaf
    assert tree.total == 13.0 and tree.values(np.array([1])).tolist() == [0.0]
    assert tree.find(np.array([1.0])).tolist() == [2]  # leaf 1 is never found at 0
    with pytest.raises(ValueError, match="finite and >= 0"):
        tree.set(np.array([0]), np.array([-1.0]))


def test_one_leaf_tree() -> None:
    tree = SumTree(1)
    tree.set(np.array([0]), np.array([2.0]))
    assert (tree.depth, tree.total, tree.find(np.array([1.5])).tolist()) == (0, 2.0, [0])


def test_sampling_follows_the_priorities() -> None:
    buf = PrioritizedReplayBuffer(8, alpha=1.0)
    _fill(buf, 4)
    # |TD errors| 0.99, 1.99, 2.99, 3.99 -> priorities 1, 2, 3, 4: probabilities 0.1 ... 0.4
    buf.update_priorities(np.arange(4), np.array([1, 2, 3, 4]) - PRIORITY_EPS)
    rng = np.random.default_rng(0)
    counts = np.zeros(4)
    for _ in range(2000):
        batch = buf.sample(10, rng)
        counts += np.bincount(batch.indices, minlength=4)
        assert np.array_equal(batch.obs[:, 0], batch.indices.astype(np.float32))  # rows match
    assert counts / counts.sum() == pytest.approx([0.1, 0.2, 0.3, 0.4], abs=0.01)


def test_importance_weights_by_hand() -> None:
    buf = PrioritizedReplayBuffer(2, alpha=1.0)
    _fill(buf, 2)
    buf.update_priorities(np.array([0, 1]), np.array([1.0, 3.0]) - PRIORITY_EPS)
    # P = 0.25, 0.75; (N P)^-1 = 2, 2/3; divided by the largest: 1, 1/3
    batch = buf.sample(4, np.random.default_rng(1), beta=1.0)  # segments of 1: leaves 0,1,1,1
    assert batch.indices.tolist() == [0, 1, 1, 1]
    weight = dict(zip(batch.indices.tolist(), batch.weights.tolist(), strict=True))
    assert weight == pytest.approx({0: 1.0, 1: 1 / 3})
    # beta 0.5: sqrt(2), sqrt(2/3); divided by sqrt(2): 1, sqrt(1/3)
    batch = buf.sample(4, np.random.default_rng(1), beta=0.5)
    weight = dict(zip(batch.indices.tolist(), batch.weights.tolist(), strict=True))
    assert weight == pytest.approx({0: 1.0, 1: (1 / 3) ** 0.5})


def test_new_transitions_get_the_largest_priority_and_alpha_flattens() -> None:
    buf = PrioritizedReplayBuffer(4, alpha=0.5)
    _fill(buf, 2)
    assert buf.tree.values(np.arange(2)).tolist() == [1.0, 1.0]
    buf.update_priorities(np.array([0]), np.array([9.0 - PRIORITY_EPS]))
    assert buf.tree.values(np.array([0])).tolist() == pytest.approx([3.0])  # 9 ** 0.5
    _fill(buf, 3)  # slots 2, 3 and (the ring wraps) 0
    assert buf.tree.values(np.arange(4)).tolist() == pytest.approx([3.0, 1.0, 3.0, 3.0])
    assert buf.tree.total == pytest.approx(10.0)


def test_priorities_survive_a_checkpoint() -> None:
    buf = PrioritizedReplayBuffer(4, alpha=1.0)
    _fill(buf, 3)
    buf.update_priorities(np.arange(3), np.array([0.5, 1.5, 4.0]))
    copy = PrioritizedReplayBuffer(4, alpha=1.0)
    copy.load_state_dict(buf.state_dict())
    assert copy.tree.values(np.arange(4)).tolist() == buf.tree.values(np.arange(4)).tolist()
    assert copy.max_priority == buf.max_priority == pytest.approx(4.0 + PRIORITY_EPS)
    state = buf.state_dict()
    del state["priorities"], state["max_priority"]  # saved by uniform replay
    copy = PrioritizedReplayBuffer(4, alpha=1.0)
    copy.load_state_dict(state)
    assert copy.tree.values(np.arange(4)).tolist() == [1.0, 1.0, 1.0, 0.0]


def test_weighted_td_loss_by_hand() -> None:
    q, target = torch.tensor([1.0, 2.0]), torch.tensor([2.0, 5.0])  # errors 1 and 3
    assert float(td_loss(q, target)) == pytest.approx(5.0)  # (1 + 9) / 2
    assert float(td_loss(q, target, weights=torch.tensor([1.0, 0.5]))) == pytest.approx(2.75)


def test_learner_reports_td_errors_and_anneals_beta() -> None:
    config = PASSENGER.replace(priority_alpha=0.6, priority_beta=0.4, priority_beta_steps=1000)
    learner = D3QNLearner(config)
    assert [learner.priority_beta(t) for t in (0, 500, 1000, 5000)] == pytest.approx(
        [0.4, 0.7, 1.0, 1.0]
    )
    buf = PrioritizedReplayBuffer(16, alpha=0.6)
    _fill(buf, 8)
    batch = buf.sample(4, np.random.default_rng(0), beta=0.4)
    rows = np.arange(4)
    q = learner.q_values(batch.obs)[rows, batch.actions]
    best_next = learner.q_values(batch.next_obs).argmax(axis=1)
    with torch.no_grad():
        next_target = learner.q_target(torch.from_numpy(batch.next_obs)).numpy()
    target = batch.rewards + 0.99 * next_target[rows, best_next]  # no terminal rows
    stats = learner.update(batch, env_steps=0)
    assert stats.abs_td_errors is not None
    assert stats.abs_td_errors == pytest.approx(np.abs(target - q), rel=1e-5)
    uniform = D3QNLearner(PASSENGER).update(batch._replace(indices=None, weights=None), 0)
    assert uniform.abs_td_errors is None
