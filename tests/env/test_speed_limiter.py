"""The speed limiter of the passenger preset: a rise that would pass the posted limit lands
on it, in the env, the safety mask and the shield; the paper's dynamics keep no limiter."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from explaindrive.agent.config import preset
from explaindrive.agent.shield import shield
from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import action_index, limited_change, limited_speed, next_speed
from explaindrive.env.safety import runtime_mask, safe_action_mask
from explaindrive.env.urban_drive import UrbanDriveEnv
from tests.env.test_right_of_way import crossroads  # noqa: F401  (a fixture)

LIMIT = 13.89  # [m/s] 50 km/h
PLUS_3 = action_index(3)


def test_a_rise_past_the_limit_lands_on_it() -> None:
    assert limited_speed(12.5, 3, LIMIT) == LIMIT  # passenger: 12.5 + 3 lands on 13.89
    assert next_speed(12.5, PLUS_3) == 15.5  # paper: no limiter
    assert next_speed(12.5, PLUS_3, LIMIT) == LIMIT
    assert limited_speed(12.5, 1, LIMIT) == 13.5  # below the limit: unchanged
    assert limited_speed(LIMIT, 1, LIMIT) == LIMIT  # holds 13.89
    assert limited_speed(12.5, -3, LIMIT) == 9.5  # braking: unchanged
    assert limited_speed(15.0, 2, LIMIT) == 14.0  # above the limit: slows by 1 m/s
    assert limited_speed(14.2, 0, LIMIT) == LIMIT  # ...down to the limit
    assert limited_speed(15.0, -1, LIMIT) == 14.0  # braking: unchanged


def test_the_change_applied_is_the_one_the_limiter_lets_through() -> None:
    assert limited_change(12.0, 3, LIMIT) == pytest.approx(1.89)  # lands on 13.89
    assert limited_change(LIMIT, 1, LIMIT) == 0.0  # holds the limit
    assert limited_change(15.0, 2, LIMIT) == -1.0  # above it: slows by 1 m/s
    assert limited_change(14.2, 0, LIMIT) == pytest.approx(-0.31)  # to the limit
    assert limited_change(12.5, 1, LIMIT) == 1  # within the limit: the action's
    assert limited_change(12.5, -3, LIMIT) == -3  # braking: the action's
    assert limited_change(12.0, 3, None) == 3  # no limiter
    assert limited_change(1.0, -3, LIMIT) == -3  # the standstill clip is not the limiter's


def _free_road(v: float) -> np.ndarray:
    """A raw observation with nothing ahead at speed ``v`` under the 13.89 m/s limit."""
    r = S.SENSOR_RANGE_M
    return np.array([float(Command.FAST), v, LIMIT, r, 0.0, r, 0.0, r], dtype=np.float32)


def test_the_mask_judges_the_speed_the_limiter_lands_on() -> None:
    obs = _free_road(12.5)
    # paper: 12.5 + 2 = 14.5 and 15.5 exceed the limit; with the limiter they land on it
    assert runtime_mask(obs).tolist() == [True] * 5 + [False] * 2
    assert runtime_mask(obs, speed_limiter=True).tolist() == [True] * 7
    # the batch rule gives the same answer as the one-row rule
    batch = np.stack([_free_road(v) for v in (0.0, 12.5, 13.0, LIMIT, 15.0)])
    rows = [safe_action_mask(x, speed_limiter=True) for x in batch]
    assert (safe_action_mask(batch, speed_limiter=True) == np.stack(rows)).all()
    # above the limit only -3 (12 m/s) and -2 (13 m/s) are back within it; -1 leaves
    # 14 m/s and so does a keep or a rise, which the limiter slows by 1 m/s
    assert runtime_mask(_free_road(15.0), speed_limiter=True).tolist() == [True] * 2 + [False] * 5
    # at 14.2 m/s (an estimate just above the limit) a keep or a rise lands on 13.89, so
    # every action stays within the limit; without the limiter only the brakings do
    assert runtime_mask(_free_road(14.2), speed_limiter=True).tolist() == [True] * 7
    assert runtime_mask(_free_road(14.2)).tolist() == [True] * 3 + [False] * 4
    # the shield keeps the fastest change at 13 m/s only with the limiter
    fastest = np.arange(7, dtype=np.float64)
    assert shield(_free_road(13.0), fastest).action == action_index(0)
    assert shield(_free_road(13.0), fastest, speed_limiter=True).action == PLUS_3


def test_only_the_passenger_preset_has_the_limiter() -> None:
    assert preset("passenger").speed_limiter
    assert not preset("paper").speed_limiter
    assert not preset("safe").speed_limiter


@pytest.mark.slow
@pytest.mark.parametrize(("limiter", "speeds", "changes"), [
    # passenger: fast holds 13.89; the step records the changes applied, 13.89 - 12 = 1.89
    (True, [3.0, 6.0, 9.0, 12.0, LIMIT, LIMIT], [3.0, 3.0, 3.0, 3.0, 1.89, 0.0]),
    # paper: speeding, judged on the true speed; every change is the action's
    (False, [3.0, 6.0, 9.0, 12.0, 15.0, 18.0], [3.0] * 6),
])  # fmt: skip
def test_the_env_holds_the_limit_with_the_limiter(
    make_env: Callable[..., UrbanDriveEnv],
    crossroads: tuple[Path, Path],  # noqa: F811
    limiter: bool,
    speeds: list[float],
    changes: list[float],
) -> None:
    net, demand = crossroads
    env = make_env(net_file=net, route=("SJ", "JN"), demand_file=demand, warmup_s=0,
                   max_steps=10, speed_limiter=limiter)  # fmt: skip
    env.reset(seed=0)
    seen, speeding, applied = [], [], []
    for _ in speeds:
        _obs, _r, _term, _trunc, info = env.step(PLUS_3)
        seen.append(info["speed_mps"])
        speeding.append(info["speeding"])
        applied.append(info["speed_change_mps"])
    assert seen == pytest.approx(speeds, abs=1e-6)
    assert applied == pytest.approx(changes, abs=1e-6)
    assert speeding == [v > LIMIT for v in speeds]
