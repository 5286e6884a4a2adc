"""scripts/krauss_whole_speeds.py: the speed factor holds Krauss below the limit's share."""

from __future__ import annotations

from types import ModuleType

import pytest

from .helpers import load_script


def _script() -> ModuleType:
    return load_script("krauss_whole_speeds")


def test_the_default_factor_is_13_mps_at_50_kmh() -> None:
    share = _script().WHOLE_SHARE_50
    assert share * 50 / 3.6 == pytest.approx(13.0)


def test_a_speed_factor_holds_krauss_under_that_share_of_the_limit() -> None:
    script = _script()
    free = script.krauss_episode(0, 0.5, None)
    held = script.krauss_episode(0, 0.5, 0.5)
    # no zone of the paper's road allows more than 50 km/h: half of it is 6.94 m/s
    assert held.mean_speed_mps <= 0.5 * 50 / 3.6
    assert held.mean_speed_mps < free.mean_speed_mps
    assert held.travel_time_s > free.travel_time_s
