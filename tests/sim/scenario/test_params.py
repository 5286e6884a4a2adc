"""Scenario parameters: the paper's road as defaults, dotted settings, range checks."""

from __future__ import annotations

import pytest

from explaindrive.config import ConfigError
from explaindrive.sim.scenario.layout import EGO_ROUTE_NODES, make_layout
from explaindrive.sim.scenario.params import ScenarioParams, min_yellow_s


def test_the_defaults_are_the_papers_road() -> None:
    plan = make_layout(ScenarioParams())
    xs = {n.id: n.x for n in plan.nodes}
    assert [xs[n] for n in EGO_ROUTE_NODES] == [0, 400, 600, 800, 1000, 1200, 1550]
    # J1: 37 + 2 * (3 + 2) + 13 = 60; J2 adds its 3 s pedestrian clearance: 34 + 10 + 3 + 13
    assert plan.tls_phase_durations_s == {"J1": (37, 3, 2, 13, 3, 2), "J2": (34, 3, 2, 13, 3, 3, 2)}
    assert plan.tls_offsets_s == {"J1": 0, "J2": 25}
    assert [f.veh_per_hour for f in plan.flows] == [900, 450, 150, 150, 180, 120, 60, 60]
    assert [round(r.speed_mps * 3.6) for r in plan.roads[:6]] == [50, 50, 30, 30, 50, 50]


def test_dotted_settings_change_one_value_each() -> None:
    p = ScenarioParams.from_settings(["limit_kmh=40", "j1.cycle_s=90", "demand.main_east=1000"])
    assert (p.limit_kmh, p.j1.cycle_s, p.j1.main_green_s, p.demand.main_east) == (40, 90, 37, 1000)
    # side green of J1 at a 90 s cycle: 90 - 37 - 2 * (3 + 2) = 43
    assert make_layout(p).tls_phase_durations_s["J1"] == (37, 3, 2, 43, 3, 2)


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        (["limit_kmh=90"], "limit_kmh: Input should be less than or equal to 70, got 90"),
        (["zone_limit_kmh=10"], "zone_limit_kmh: Input should be greater than or equal to 20"),
        (["approach_m=20"], "approach_m: Input should be greater than or equal to 60"),
        (["j1.colour=1"], "j1.colour: Extra inputs are not permitted"),
        (["nope.x=1"], "unknown scenario key 'nope.x'"),
        (["limit_kmh"], "must look like KEY=VALUE"),
        # 40 s cycle, 30 s main green: the side road keeps 40 - 30 - 10 = 0 s
        (["j1.cycle_s=40", "j1.main_green_s=30"], "j1: the side road's green would be 0 s"),
        (["j2.offset_s=70"], "j2: offset_s must be below cycle_s (60)"),
        # a 100 m turn lane in an 110 m block would start 10 m after Z2
        (
            ["zone_end_to_j2_m=110", "turn_lane_m=100"],
            "turn_lane_m 100 m leaves under 20 m of its block zone_end_to_j2_m (110 m)",
        ),
        (
            ["j1_to_zone_m=70", "joined_junction_m=60"],
            "joined_junction_m 60 m leaves under 20 m of its block j1_to_zone_m (70 m)",
        ),
        (["turn_lane_m=30"], "turn_lane_m: Input should be greater than or equal to 40"),
    ],
)
def test_bad_settings_are_named(settings: list[str], message: str) -> None:
    with pytest.raises(ConfigError, match=None) as err:
        ScenarioParams.from_settings(settings)
    assert message in str(err.value)


@pytest.mark.parametrize(("limit_kmh", "yellow_s"), [(30, 3), (50, 3), (60, 4), (70, 4)])
def test_the_shortest_yellow_leaves_no_dilemma_zone(limit_kmh: float, yellow_s: int) -> None:
    assert min_yellow_s(limit_kmh) == yellow_s


def test_a_yellow_too_short_for_the_road_is_refused() -> None:
    # 60 km/h: at 16 m/s braking by 3 needs 13 + 10 + 7 + 4 + 1 + 2 = 37 m, and 2 steps at
    # 16 m/s cover 32 m: a car that sees a 3 s yellow 33-36 m out can neither stop nor cross
    with pytest.raises(
        ConfigError, match="j1: yellow_s 3 s is too short for a 60 km/h road; at least 4 s"
    ):
        ScenarioParams.from_settings(["limit_kmh=60"])
    p = ScenarioParams.from_settings(["limit_kmh=60", "j1.yellow_s=4", "j2.yellow_s=4"])
    assert (p.j1.yellow_s, p.j2.yellow_s) == (4, 4)
