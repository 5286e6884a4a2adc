"""Synthetic boundary observations: where they land and what their masks say."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from explaindrive.agent.boundary import BOUNDARY_SPAN, boundary_batch, boundary_observations
from explaindrive.agent.buffer import ReplayBatch
from explaindrive.agent.config import PASSENGER
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.shield import training_mask
from explaindrive.config import ConfigError
from explaindrive.env import state as S
from explaindrive.env.actions import stopping_needs

R = S.SENSOR_RANGE_M
# cmd, v, v_lim, gap, dv, d_tl, tls, d_cross
FOLLOWING = [1.0, 10.0, 13.89, 40.0, 4.0, R, 0.0, R]  # a leader at 6 m/s, 40 m ahead
RED_AHEAD = [1.0, 8.0, 13.89, 60.0, 8.0, 60.0, 2.0, 90.0]  # a red line as leader, a crossing
EMPTY = [0.0, 12.0, 13.89, R, 0.0, R, 0.0, R]


def _synthetic(rows: list[list[float]], n: int = 4000, seed: int = 0) -> np.ndarray:
    obs = np.repeat(np.asarray(rows, dtype=np.float32), n, axis=0)
    return boundary_observations(obs, np.random.default_rng(seed))


def test_speed_moves_by_whole_steps_and_the_leader_keeps_its_speed() -> None:
    x = _synthetic([FOLLOWING])
    assert set(np.unique(x[:, S.V_EGO]).tolist()) == {8.0, 9.0, 10.0, 11.0, 12.0}
    assert np.allclose(x[:, S.V_EGO] - x[:, S.DV], 6.0)  # leader speed v - dv stays 6 m/s
    assert np.allclose(x[:, [S.CMD, S.V_LIM, S.D_TL, S.TLS, S.D_CROSS]], [1.0, 13.89, R, 0.0, R])


def test_the_nearest_object_lands_near_the_stopping_need() -> None:
    x = _synthetic([FOLLOWING])
    limit = BOUNDARY_SPAN * (stopping_needs(x[:, S.V_EGO].astype(np.float64) + 3.0) + 1.0)
    assert np.all(x[:, S.D_LEAD] <= limit + 1e-4) and np.all(x[:, S.D_LEAD] >= 0.0)
    # uniform over [0, limit]: about half below half the limit
    assert np.mean(x[:, S.D_LEAD] < limit / 2) == pytest.approx(0.5, abs=0.03)


def test_distances_scale_together_so_the_line_stays_the_leader() -> None:
    x = _synthetic([RED_AHEAD])
    assert np.allclose(x[:, S.D_LEAD], x[:, S.D_TL])
    assert np.allclose(x[:, S.D_CROSS], np.minimum(1.5 * x[:, S.D_TL], R - 1.0), rtol=1e-5)
    close = _synthetic([[1.0, 8.0, 13.89, 2.0, 2.0, R, 0.0, 150.0]])  # leader 2 m, crossing
    assert close[:, S.D_CROSS].max() == R - 1.0  # scaled up past the range: kept inside it
    assert np.allclose(x[:, S.DV], x[:, S.V_EGO])  # the line stands still
    assert np.all(x[:, S.TLS] == 2.0)


def test_an_empty_road_gets_a_red_light_half_of_the_time() -> None:
    x = _synthetic([EMPTY])
    red = x[:, S.TLS] == 2.0
    assert red.mean() == pytest.approx(0.5, abs=0.03)
    assert np.allclose(x[red, S.D_LEAD], x[red, S.D_TL]) and np.allclose(
        x[red, S.DV], x[red, S.V_EGO]
    )
    assert np.all(x[~red][:, [S.D_LEAD, S.DV, S.D_TL, S.D_CROSS]] == [R, 0.0, R, R])


def test_the_masks_are_the_rules_and_many_rows_sit_on_the_boundary() -> None:
    obs = np.asarray([FOLLOWING, RED_AHEAD, EMPTY] * 500, dtype=np.float32)
    synthetic, mask = boundary_batch(obs, np.random.default_rng(3), dilemma_braking=True)
    assert np.array_equal(mask, training_mask(synthetic, True))
    # a worked row: 3 m/s, a red line 1.9 m ahead (the light a network ran easing off by
    # 1 m/s per step): only the hardest braking is safe
    row = np.asarray([1.0, 3.0, 13.89, 1.9, 3.0, 1.9, 2.0, R], dtype=np.float32)
    assert training_mask(row, True).tolist() == [True] + [False] * 6
    # the original rows forbid no braking or keeping; the synthetic ones straddle every
    # action's boundary: the stronger the action, the more rows forbid it
    assert not (~training_mask(obs, True))[:, :4].any()
    unsafe_share = (~mask).mean(axis=0)
    assert unsafe_share[0] == 0.0 and np.all(np.diff(unsafe_share[1:]) > 0.05)
    assert unsafe_share[1] > 0.15 and unsafe_share[6] < 0.95


def test_the_masks_read_the_speed_limiter_when_it_is_on() -> None:
    obs = np.asarray([FOLLOWING, RED_AHEAD, EMPTY] * 500, dtype=np.float32)
    plain, plain_mask = boundary_batch(obs, np.random.default_rng(5), True)
    limited, mask = boundary_batch(obs, np.random.default_rng(5), True, speed_limiter=True)
    np.testing.assert_array_equal(limited, plain)  # the same rows, drawn the same way
    assert np.array_equal(mask, training_mask(limited, True, True))
    # an empty road at 13 m/s (EMPTY's 12 m/s moved by +1): +1 is over the limit (14 m/s)
    # without the limiter and lands on 13.89 with it
    free_13 = (
        (limited[:, S.V_EGO] == 13.0) & (limited[:, S.D_LEAD] >= R) & (limited[:, S.TLS] == 0.0)
    )
    assert free_13.any()
    assert not plain_mask[free_13, 4].any() and mask[free_13, 4].all()


def test_noisy_rows_keep_the_masks_of_the_rows_without_noise() -> None:
    obs = np.asarray([FOLLOWING, RED_AHEAD, EMPTY] * 2000, dtype=np.float32)
    clean, clean_mask = boundary_batch(obs, np.random.default_rng(4), True)
    rng = np.random.default_rng(4)
    seen, mask = boundary_batch(obs, rng, True, noise_max=(3.0, 0.9), noisy_share=0.5)
    np.testing.assert_array_equal(mask, clean_mask)  # the same synthetic rows, the same masks
    moved = seen[:, S.V_EGO] != clean[:, S.V_EGO]
    assert moved.mean() == pytest.approx(0.5, abs=0.03)  # noisy_share of the rows
    # deviations uniform in [0, 0.9]: the mean absolute error is 0.45 * sqrt(2 / pi)
    error = np.abs(seen[moved, S.V_EGO] - clean[moved, S.V_EGO])
    assert error.mean() == pytest.approx(0.45 * np.sqrt(2 / np.pi), rel=0.08)
    assert np.all(seen[~moved] == clean[~moved])
    # a seen speed well under the limit whose true speed is at it: +1 is unsafe there
    at_limit = (clean[:, S.V_EGO] >= 13.0) & (seen[:, S.V_EGO] < 12.0) & (clean[:, S.TLS] == 0)
    assert at_limit.any() and not mask[at_limit, 4].any()


def test_without_noise_nothing_more_is_drawn() -> None:
    obs = np.asarray([FOLLOWING, RED_AHEAD], dtype=np.float32)
    a, b = np.random.default_rng(1), np.random.default_rng(1)
    boundary_batch(obs, a, True)
    boundary_batch(obs, b, True, noise_max=(3.0, 0.9), noisy_share=0.0)
    assert a.random() == b.random()


def test_boundary_noise_needs_noise_and_rows() -> None:
    with pytest.raises(ConfigError, match="boundary_noise needs obs_noise_max and boundary_wei"):
        PASSENGER.replace(boundary_noise=True, obs_noise_max=(0.0, 0.0))
    with pytest.raises(ConfigError, match="boundary_noise needs"):
        PASSENGER.replace(boundary_noise=True, boundary_weight=0.0)
    assert PASSENGER.replace(boundary_noise=True).boundary_noise


def test_boundary_loss_pushes_the_unsafe_actions_of_synthetic_rows_down() -> None:
    config = PASSENGER.replace(boundary_weight=1.0, lr=1e-2, lr_final=None)
    learner = D3QNLearner(config)
    row = np.asarray([[1.0, 3.0, 13.89, 1.9, 3.0, 1.9, 2.0, R]], dtype=np.float32)
    mask = training_mask(row, True)
    batch = ReplayBatch(
        obs=row, actions=np.array([0]), rewards=np.zeros(1, np.float32), next_obs=row,
        terminated=np.ones(1, bool), discount=np.ones(1, np.float32),
        mask=np.ones((1, 7), bool), next_mask=np.ones((1, 7), bool),
    )  # fmt: skip
    for _ in range(200):
        stats = learner.update(batch, 0, (row, mask))
    q = learner.q_values(row)[0]
    assert int(np.argmax(q)) == 0  # only the boundary loss says so: the stored mask is all-safe
    assert stats.boundary_loss < 1.0
    with torch.no_grad():
        assert float(learner.q(torch.from_numpy(row))[0, 0]) == pytest.approx(q[0])


@pytest.mark.parametrize("boundary_margin", [None, 5.0])
def test_the_boundary_rows_have_their_own_margin(boundary_margin: float | None) -> None:
    # A row 3 m before a red line at 13.89 m/s: only -3 is safe. The loss on it is the summed
    # squared excess of the six unsafe values over (best safe - margin), computed by hand
    # from the values before the update; the margin is unsafe_margin (30) unless set.
    config = PASSENGER.replace(boundary_weight=1.0, boundary_margin=boundary_margin, loss="mse")
    learner = D3QNLearner(config)
    row = np.asarray([[1.0, 3.0, 13.89, 1.9, 3.0, 1.9, 2.0, R]], dtype=np.float32)
    mask = training_mask(row, True)
    assert mask[0].tolist() == [True] + [False] * 6
    q = learner.q_values(row)[0].astype(np.float64)
    margin = 30.0 if boundary_margin is None else boundary_margin
    expected = float(np.sum(np.maximum(q[1:] - (q[0] - margin), 0.0) ** 2))
    batch = ReplayBatch(
        obs=row, actions=np.array([0]), rewards=np.zeros(1, np.float32), next_obs=row,
        terminated=np.ones(1, bool), discount=np.ones(1, np.float32),
        mask=np.ones((1, 7), bool), next_mask=np.ones((1, 7), bool),
    )  # fmt: skip
    stats = learner.update(batch, 0, (row, mask))
    assert stats.boundary_loss == pytest.approx(expected, rel=1e-4)
    assert expected > 6 * (margin - 1.0) ** 2  # the fresh network's values are near zero
