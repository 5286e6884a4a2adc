"""The posted limit before a lower speed zone."""

from __future__ import annotations

import math

import pytest

from explaindrive.sim.route import RouteGeometry

# 50 km/h, then 30 km/h from 600 m to 1000 m, then 50 km/h again
ROAD = RouteGeometry(
    edges=("a",), edge_start_m=(0.0,), length_m=1500.0, zone_start_m=(0.0, 600.0, 1000.0),
    zone_limit_mps=(13.89, 8.33, 13.89), lights=(), crossings=(),
)  # fmt: skip


def test_the_posted_limit_ramps_down_to_the_zone():
    assert ROAD.posted_limit(400.0) == 13.89  # far away: the legal limit
    # 40 m ahead: v^2 + 1.5 v = 8.33^2 + 1.5 * 40 -> v = -0.75 + sqrt(0.5625 + 129.3889)
    assert ROAD.posted_limit(560.0) == pytest.approx(-0.75 + math.sqrt(0.5625 + 129.3889))
    assert ROAD.posted_limit(598.0) == 8.33  # never below the zone's own limit
    assert ROAD.posted_limit(700.0) == 8.33  # in the zone
    assert ROAD.posted_limit(990.0) == 8.33  # a higher zone ahead is not anticipated
    assert ROAD.posted_limit(1000.0) == 13.89


@pytest.mark.parametrize("speed", [13.0, 12.0, 11.0, 9.0])
@pytest.mark.parametrize("offset", [0.0, 0.7, 3.3, 6.1, 9.9, 12.5])
def test_a_driver_who_keeps_to_it_brakes_gently_and_never_speeds(speed, offset):
    pos, v, hardest = 400.0 - offset, speed, 0.0
    while pos < 700.0:
        v_new = min(v, math.floor(ROAD.posted_limit(pos) + 1e-9))  # whole m/s, as the actions
        hardest = max(hardest, v - v_new)
        pos, v = pos + v_new, v_new  # SUMO moves the car by its new speed
        assert v <= ROAD.limit_at(pos) + 1e-9
    assert hardest <= 1.0
