"""Ride-quality figures against hand-computed numbers."""

import math

import pytest

from explaindrive.env.ride_quality import RideQuality, free_road, is_free_road, signal_stop_kind
from explaindrive.evaluation.aggregate import ride_quality

LIMIT = 10.0


def info(speed, accel=0.0, jerk=0.0, command="fast", **kw):
    base = {
        "speed_mps": speed, "accel_mps2": accel, "jerk_mps3": jerk, "command": command,
        "posted_limit_mps": LIMIT, "real_gap_m": math.inf, "gap_m": math.inf,
        "leader_virtual": False, "light_gap_m": 200.0, "light_state": "green",
        "crossing_gap_m": 200.0,
    }  # fmt: skip
    base.update(kw)
    return base


def test_free_road_needs_no_vehicle_light_or_pedestrian_close():
    assert is_free_road(info(5.0))
    assert not is_free_road(info(5.0, real_gap_m=49.0))
    assert is_free_road(info(5.0, real_gap_m=50.0))
    assert not is_free_road(info(5.0, light_state="red", light_gap_m=59.0))
    assert is_free_road(info(5.0, light_state="green", light_gap_m=10.0))
    assert is_free_road(info(5.0, light_state="yellow", light_gap_m=60.0))
    assert not is_free_road(info(5.0, crossing_gap_m=30.0))


def test_signal_stop_kind():
    assert signal_stop_kind(info(0.0, gap_m=3.0, real_gap_m=3.0)) is None  # a car ahead
    red = info(0.0, gap_m=3.0, leader_virtual=True, light_state="red", light_gap_m=3.0)
    assert signal_stop_kind(red) == "light"
    ped = info(0.0, gap_m=2.0, leader_virtual=True, crossing_gap_m=2.0)
    assert signal_stop_kind(ped) == "crossing"


def test_figures_of_a_short_ride():
    q = RideQuality()
    q.update(info(3.0, accel=3.0, jerk=3.0))  # free, 30 % of the limit: slow
    q.update(info(8.0, accel=5.0, jerk=2.0))  # free, 80 %
    q.update(info(6.0, accel=-2.0, jerk=-7.0, real_gap_m=20.0))  # following: first strong a
    q.update(info(8.0, accel=2.0, jerk=4.0, real_gap_m=20.0))  # reversal 1
    q.update(info(5.0, accel=-3.0, jerk=-5.0, real_gap_m=20.0))  # reversal 2, hard brake
    q.update(info(5.0, accel=0.0, jerk=3.0, real_gap_m=80.0))  # free again: 50 %, slow
    q.update(info(2.0, accel=-3.0, jerk=-3.0, command="stop"))  # under STOP: left out
    q.update(info(0.0, accel=-2.0, jerk=1.0, gap_m=4.0, leader_virtual=True,
                  light_state="red", light_gap_m=4.0))  # fmt: skip
    r = q.result()
    assert r.steps == 7
    # free road: steps 1, 2, 6 (step 8 has a red light 4 m ahead)
    assert (r.free_road_steps, r.slow_free_road_steps) == (3, 2)
    assert r.free_road_speed_sum == pytest.approx(0.3 + 0.8 + 0.5)
    assert (r.hard_brakes, r.following_steps, r.reversals) == (1, 3, 2)
    assert r.jerky_steps == 5  # |jerk| 3, 7, 4, 5, 3
    assert r.light_stop_gaps_m == (4.0,) and r.crossing_stop_gaps_m == ()


def test_a_stop_that_starts_before_standstill_is_counted_once():
    q = RideQuality()
    stand = {"leader_virtual": True, "crossing_gap_m": 2.5, "gap_m": 2.5}
    for speed in (4.0, 1.0, 0.0, 0.0, 0.0):
        q.update(info(speed, **stand))
    assert q.result().crossing_stop_gaps_m == (2.5,)


def test_pooled_figures():
    q1, q2 = RideQuality(), RideQuality()
    for _ in range(3):
        q1.update(info(10.0))
    q1.update(info(0.0, accel=-3.0, gap_m=2.0, leader_virtual=True, crossing_gap_m=2.0))
    q2.update(info(3.0, accel=-3.0, real_gap_m=10.0))
    q2.update(info(0.0, accel=-3.0, gap_m=8.0, leader_virtual=True, light_state="red",
                   light_gap_m=8.0))  # fmt: skip
    agg = ride_quality([q1.result(), q2.result()], distance_m=500.0)
    assert agg["free_road_speed_share"] == pytest.approx(1.0)  # 3 free steps at the limit
    assert agg["slow_free_road_share"] == 0.0
    assert agg["hard_brakes_per_episode"] == 1.5  # 3 / 2
    assert agg["hard_brakes_per_km"] == 6.0  # 3 / 0.5 km
    assert agg["reversals_per_min"] == 0.0  # 1 following step, no reversal
    assert agg["stop_gap_in_window_share"] == 0.5  # 2 m in [1, 5], 8 m not
    assert (agg["light_stops"], agg["crossing_stops"]) == (1, 1)


@pytest.mark.parametrize(
    ("real_gap_m", "red_or_yellow", "light_gap_m", "crossing_gap_m", "free"),
    [
        (50.0, False, 10.0, 200.0, True),  # a green light close by does not matter
        (49.9, False, 200.0, 200.0, False),  # a vehicle within 50 m
        (200.0, True, 59.9, 200.0, False),  # a red or yellow light within 60 m
        (200.0, True, 60.0, 200.0, True),
        (200.0, False, 200.0, 59.9, False),  # a pedestrian on a crossing within 60 m
    ],
)
def test_free_road_is_judged_at_50_m_of_vehicles_and_60_m_of_signals(
    real_gap_m, red_or_yellow, light_gap_m, crossing_gap_m, free
):
    assert free_road(real_gap_m, red_or_yellow, light_gap_m, crossing_gap_m) is free
