"""scripts/probe_policy.py's free road under speed noise, on threshold drivers worked by hand."""

from __future__ import annotations

from types import ModuleType, SimpleNamespace

import numpy as np
import pytest
import torch

from explaindrive.env import state as S
from explaindrive.env.actions import action_index

from .helpers import load_script


def _probe() -> ModuleType:
    return load_script("probe_policy")


def _threshold(below: float) -> SimpleNamespace:
    """A driver that accelerates by 1 m/s while it reads a speed under ``below``, else holds."""

    def network(obs: torch.Tensor) -> torch.Tensor:
        q = torch.zeros(len(obs), 7)
        up = obs[:, S.V_EGO] < below
        q[up, action_index(1)] = 1.0
        q[~up, action_index(0)] = 1.0
        return q

    return SimpleNamespace(network=network)


def test_without_noise_the_chain_climbs_a_step_at_a_time() -> None:
    # from 0: 1, 2, ..., 13 after 13 steps, then 13 for the remaining 987 (13 > 12.9)
    mean, over = _probe().noisy_cruise(_threshold(12.5), 1, 12.9, 0.0, 0.0, draws=10)
    assert mean == pytest.approx((sum(range(1, 14)) + 13 * 987) / 1000)
    assert over == pytest.approx(988.0)


def test_a_driver_that_never_speeds_up_stays_where_it_is() -> None:
    mean, over = _probe().noisy_cruise(_threshold(-1.0), 1, 13.89, 12.0, 0.6, draws=2000)
    assert (mean, over) == (pytest.approx(12.0), 0.0)


def test_noise_lets_a_reading_under_the_threshold_take_the_car_over() -> None:
    # At 12 m/s with the threshold at 12: half of the readings are under it. The next whole
    # speed 13 is over a 12.9 limit; there a reading under 12 (1.67 sd at 0.6) still climbs.
    mean, over = _probe().noisy_cruise(_threshold(12.0), 1, 12.9, 12.0, 0.6, draws=20_000)
    assert mean > 12.5 and over > 900


def _always_up() -> SimpleNamespace:
    """A driver that always asks for +1 m/s."""

    def q_values(obs: np.ndarray) -> np.ndarray:
        q = np.zeros(7)
        q[action_index(1)] = 1.0
        return q

    return SimpleNamespace(q_values=q_values)


def test_through_the_limiter_a_driver_that_always_rises_settles_on_the_limit():
    probe = _probe()
    settled, gap = probe.free_road(_always_up(), 1, 13.89, limiter=True)
    assert settled == pytest.approx(13.89) and gap == 0.0  # +1 is its best action there
    # without the limiter it climbs by 1 m/s a step to the top of the speed range
    assert probe.free_road(_always_up(), 1, 13.89)[0] == S.MAX_SPEED_MPS
