"""The replay ring buffer."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.agent.buffer import ReplayBuffer, Transition, replay_nbytes


def _add(buf: ReplayBuffer, start: int, n: int) -> None:
    ids = np.arange(start, start + n, dtype=np.float32)
    obs = np.repeat(ids[:, None], 8, axis=1)
    mask = np.zeros((n, 7), dtype=bool)
    mask[np.arange(n), ids.astype(np.int64) % 7] = True
    buf.add(obs, ids.astype(np.int64) % 7, ids, obs + 0.5, ids % 2 == 0, 0.99**3, mask, ~mask)


def test_ring_overwrites_the_oldest() -> None:
    buf = ReplayBuffer(4)
    _add(buf, 0, 3)
    assert (len(buf), buf.pos) == (3, 3)
    _add(buf, 3, 3)  # items 3, 4, 5 -> slots 3, 0, 1
    assert (len(buf), buf.pos) == (4, 2)
    assert buf.obs[:, 0].tolist() == [4.0, 5.0, 2.0, 3.0]
    assert buf.next_obs[:, 0].tolist() == [4.5, 5.5, 2.5, 3.5]
    assert buf.rewards.tolist() == [4.0, 5.0, 2.0, 3.0]
    assert buf.terminated.tolist() == [True, False, True, False]
    assert buf.discount.tolist() == pytest.approx([0.970299] * 4)
    assert buf.mask.argmax(axis=1).tolist() == [4, 5, 2, 3]  # the action's slot, as added
    assert (buf.next_mask.sum(axis=1) == 6).all()
    with pytest.raises(ValueError, match="cannot add 5"):
        _add(buf, 0, 5)


def test_extend_stores_transitions_as_rollouts_ship_them() -> None:
    buf = ReplayBuffer(4)
    safe = np.array([True, True, False, False, False, False, False])
    steps = [
        Transition(np.full(8, 1.0), 2, 0.5, np.full(8, 2.0), False, 0.25, safe, ~safe),
        Transition(np.full(8, 2.0), 6, -1.0, np.full(8, 3.0), True, 0.5, ~safe, safe),
    ]
    buf.extend(steps)
    buf.extend([])  # a round without transitions adds nothing
    assert (len(buf), buf.pos) == (2, 2)
    assert buf.obs[:2, 0].tolist() == [1.0, 2.0] and buf.next_obs[:2, 7].tolist() == [2.0, 3.0]
    assert buf.actions[:2].tolist() == [2, 6] and buf.rewards[:2].tolist() == [0.5, -1.0]
    assert buf.terminated[:2].tolist() == [False, True]
    assert buf.discount[:2].tolist() == [0.25, 0.5]
    assert buf.mask[:2].sum(axis=1).tolist() == [2, 5]
    assert buf.next_mask[:2].sum(axis=1).tolist() == [5, 2]


def test_sample_returns_consistent_rows() -> None:
    buf = ReplayBuffer(10)
    _add(buf, 0, 6)
    batch = buf.sample(32, np.random.default_rng(0))
    assert batch.obs.shape == (32, 8) and batch.actions.dtype == np.int64
    assert set(batch.rewards.tolist()) <= {0.0, 1.0, 2.0, 3.0, 4.0, 5.0}
    assert np.array_equal(batch.obs[:, 0], batch.rewards)
    assert np.array_equal(batch.next_obs[:, 0], batch.rewards + 0.5)
    assert np.array_equal(batch.mask.argmax(axis=1), batch.actions)
    assert not (batch.mask & batch.next_mask).any()
    with pytest.raises(ValueError, match="empty"):
        ReplayBuffer(3).sample(1, np.random.default_rng(0))


def test_paper_capacity_fits_well_under_one_gigabyte() -> None:
    # 5M x (2 x 8 x 4 B states + 1 B action + 4 B reward + 4 B discount + 1 B flag
    # + 2 x 7 B masks) = 5M x 88 B = 440 MB
    assert replay_nbytes(5_000_000) == 440_000_000
    buf = ReplayBuffer(5_000_000)  # np.zeros: pages are only committed when written
    assert buf.nbytes == 440_000_000 < 1 << 30


def test_missing_masks_allow_every_action() -> None:
    buf = ReplayBuffer(2)
    buf.add(np.zeros((1, 8)), np.array([3]), np.array([1.0]), np.zeros((1, 8)), np.array([0]), 0.9)
    assert buf.mask[0].all() and buf.next_mask[0].all() and buf.discount[0] == pytest.approx(0.9)


def test_state_dict_round_trip() -> None:
    buf = ReplayBuffer(4)
    _add(buf, 0, 3)
    _add(buf, 3, 3)
    other = ReplayBuffer(4)
    other.load_state_dict(buf.state_dict())
    assert (len(other), other.pos) == (4, 2)
    assert np.array_equal(other.obs, buf.obs) and np.array_equal(other.actions, buf.actions)
    assert np.array_equal(other.mask, buf.mask) and np.array_equal(other.discount, buf.discount)
    old = {k: v for k, v in buf.state_dict().items() if k != "next_mask"}
    with pytest.raises(ValueError, match="lacks next_mask"):
        ReplayBuffer(4).load_state_dict(old)
    with pytest.raises(ValueError, match="capacity 4"):
        ReplayBuffer(8).load_state_dict(buf.state_dict())
