"""The ego's route position anchored to the edge it is on: positions worked out by hand on a
made-up route whose lanes are longer than the route's reference lanes."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest

from explaindrive.env.odometer import RouteOdometer
from explaindrive.sim.route import RouteGeometry

# edges a (0-100 m), a junction (100-110 m), b (110-210 m); the ego drives lanes a_1 and b_1,
# each 105 m long (a curve's outer lane), where the reference lanes are 100 m
GEOMETRY = RouteGeometry(
    edges=("a", "b"), edge_start_m=(0.0, 110.0), length_m=210.0, zone_start_m=(0.0,),
    zone_limit_mps=(13.89,), lights=(), crossings=(), edge_stop_m=(100.0, 210.0),
)  # fmt: skip
API: Any = SimpleNamespace(lane=SimpleNamespace(getLength=lambda lane: 105.0))


def test_on_an_edge_the_position_is_the_share_of_the_lane_driven() -> None:
    odo = RouteOdometer(GEOMETRY, 0.0)
    # halfway along a_1 (52.5 of 105 m) is halfway along a: 50 m, not the 52.5 m driven
    assert odo(API, "a_1", 52.5, 52.5) == pytest.approx(50.0)
    # its end is a's stop line
    assert odo(API, "a_1", 105.0, 105.0) == pytest.approx(100.0)
    # 21 m onto b_1 (a fifth of it): 110 + 20 m
    assert odo(API, "b_1", 21.0, 141.0) == pytest.approx(130.0)


def test_inside_a_junction_it_counts_the_distance_driven_up_to_the_next_edge() -> None:
    odo = RouteOdometer(GEOMETRY, 0.0)
    odo(API, "a_1", 105.0, 105.0)  # 100 m
    assert odo(API, ":J_0_0", 4.0, 109.0) == pytest.approx(104.0)
    # a junction lane longer than the route's (12 m driven, 10 m laid out): held at b's start
    assert odo(API, ":J_0_0", 12.0, 117.0) == pytest.approx(110.0)
    assert odo(API, "b_1", 0.0, 117.0) == pytest.approx(110.0)


def test_the_position_never_decreases_and_entry_midway_counts() -> None:
    odo = RouteOdometer(GEOMETRY, 130.0)  # entered on b, 20 m along it
    # SUMO's lane position lags the entry by a step: the position holds
    assert odo(API, "b_1", 19.0, 0.0) == pytest.approx(130.0)
    assert odo(API, "b_1", 42.0, 21.0) == pytest.approx(150.0)


def test_a_geometry_without_stop_lines_lays_each_edge_out_to_the_next_start() -> None:
    plain = RouteGeometry(
        edges=("a", "b"), edge_start_m=(0.0, 110.0), length_m=210.0, zone_start_m=(0.0,),
        zone_limit_mps=(13.89,), lights=(), crossings=(),
    )  # fmt: skip
    assert plain.edge_end_m(0) == 110.0 and plain.edge_end_m(1) == 210.0
    assert GEOMETRY.edge_end_m(0) == 100.0
    assert RouteOdometer(plain, 0.0)(API, "a_1", 52.5, 52.5) == pytest.approx(55.0)
