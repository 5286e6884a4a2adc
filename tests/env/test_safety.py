"""One observation's mask (the rule in plain Python, the speed's outcomes kept) is its row of
the batch mask (the rule vectorised), over random and edge-case observations."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from explaindrive.env import state as S
from explaindrive.env.safety import limit_mask, runtime_mask, safe_action_mask, training_mask

INTEGER_SPEEDS = (0, 0.5, 1, 2, 2.9999, 3, 3.0000002, 4, 6, 9, 12, 13, 14, 17, 20, 23, -1)
NEEDS_M = (0, 3, 4, 7, 11, 14, 17, 24, 32, 37, 49, 55, 63, 74, 98, 102)  # of integer speeds


def observations(n: int, seed: int = 0) -> np.ndarray:
    """Random raw observations with the edges of the rule: integer speeds, distances at the
    stopping needs and at sensor range, leaders at the stop lines within and beyond the
    virtual-leader tolerance, non-integer codes and a few NaN components."""
    rng = np.random.default_rng(seed)
    o = np.empty((n, S.STATE_DIM), dtype=np.float32)
    o[:, S.CMD] = rng.choice([0, 1, 2, 0.4, 1.6], n)
    o[:, S.V_EGO] = np.where(
        rng.random(n) < 0.6, rng.choice(INTEGER_SPEEDS, n), rng.uniform(-1, 24, n)
    )
    o[:, S.V_LIM] = rng.choice([0, 5, 8.33, 11.11, 13.89, 16.67, 20], n)
    o[:, S.DV] = rng.uniform(-20, 20, n)
    o[:, S.TLS] = rng.choice([0, 1, 2, 0.6, 1.4], n)
    for col in (S.D_LEAD, S.D_TL, S.D_CROSS):
        o[:, col] = np.where(rng.random(n) < 0.4, S.SENSOR_RANGE_M, rng.uniform(0, 210, n))
        at_need = rng.random(n) < 0.15
        o[at_need, col] = rng.choice(NEEDS_M, at_need.sum())
    for line in (S.D_TL, S.D_CROSS):
        at_line = rng.random(n) < 0.2
        offsets = rng.choice([0, 0.49, 0.5, 0.51, -0.5, -0.6], at_line.sum())
        o[at_line, S.D_LEAD] = o[at_line, line] + offsets
    nan = np.flatnonzero(rng.random(n) < 0.01)
    o[nan, rng.integers(0, S.STATE_DIM, nan.size)] = np.nan
    return o


@pytest.mark.parametrize(
    ("dilemma_braking", "stop_progress"), list(itertools.product([False, True], repeat=2))
)
def test_one_observation_is_its_row_of_the_batch(
    dilemma_braking: bool, stop_progress: bool
) -> None:
    rows = observations(5000)
    batch = safe_action_mask(rows, dilemma_braking, stop_progress)
    for row, expected in zip(rows, batch, strict=True):
        mask = safe_action_mask(row, dilemma_braking, stop_progress)
        assert mask.dtype == np.bool_ and mask.shape == (7,)
        np.testing.assert_array_equal(mask, expected, err_msg=str(row))


@pytest.mark.parametrize("mask_of", [runtime_mask, training_mask, limit_mask])
def test_the_masks_of_one_observation_are_their_rows(mask_of) -> None:
    rows = observations(3000, seed=1)
    batch = mask_of(rows)
    for row, expected in zip(rows, batch, strict=True):
        np.testing.assert_array_equal(mask_of(row), expected, err_msg=str(row))


def test_a_batch_of_one_is_a_batch() -> None:
    row = observations(1, seed=2)
    assert safe_action_mask(row).shape == (1, 7)
    np.testing.assert_array_equal(safe_action_mask(row)[0], safe_action_mask(row[0]))


def test_kept_outcomes_are_not_changed_by_a_mask() -> None:
    obs = np.array([0, 0, 13.89, 200, 0, 200, 0, 200], dtype=np.float32)
    first = runtime_mask(obs)
    first[:] = False  # a caller's copy: changing it leaves the next mask as it was
    np.testing.assert_array_equal(
        runtime_mask(obs), safe_action_mask(obs[None], stop_progress=True)[0]
    )


@pytest.mark.parametrize(
    "outside",
    [
        lambda o: o[:, S.D_CROSS] >= S.SENSOR_RANGE_M,  # no crossing in range
        lambda o: (o[:, S.D_TL] >= S.SENSOR_RANGE_M) | (np.rint(o[:, S.TLS]) == 0),  # no light
        lambda o: o[:, S.D_LEAD] >= S.SENSOR_RANGE_M,  # no leader
        lambda o: np.rint(o[:, S.CMD]) != 2,  # no STOP
    ],
)
def test_a_batch_where_a_rule_never_applies_is_its_rows(outside) -> None:
    rows = observations(4000, seed=3)
    rows = rows[outside(rows)]
    assert len(rows) > 100
    batch = runtime_mask(rows)
    for row, expected in zip(rows, batch, strict=True):
        np.testing.assert_array_equal(runtime_mask(row), expected, err_msg=str(row))
