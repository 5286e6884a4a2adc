"""Right of way: the rule's and the judge's times worked out by hand, and on a priority
crossroads built by netconvert, a yield line that is a virtual leader while a foe with
priority approaches, and entering the conflict area in front of it a yield violation."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from explaindrive.agent.shield import shield
from explaindrive.env import state as S
from explaindrive.env.right_of_way import (
    CONFLICT_HALF_M,
    YIELD_JUDGE_GAP_S,
    YIELD_MARGIN_S,
    FoeMotion,
    JunctionFoe,
    TurnGeometry,
    YieldSensor,
    arrival_time_s,
    clear_time_s,
    crossing_offsets,
    enters_in_front,
    foe_window_s,
    junction_of,
    link_yields,
    must_yield,
    turn_foe,
    turn_geometry,
)
from explaindrive.env.urban_drive import UrbanDriveEnv
from tests.conftest import NO_DEMAND, plain_net

# A crossroads J of a priority road W-E (priority 3) and a minor road S-N (priority 1), each
# one lane a way at 13.89 m/s; J is an unsignalised priority junction.
NODES = """<nodes>
  <node id="W" x="-300" y="0" type="priority"/>
  <node id="J" x="0" y="0" type="priority"/>
  <node id="E" x="300" y="0" type="priority"/>
  <node id="S" x="0" y="-300" type="priority"/>
  <node id="N" x="0" y="300" type="priority"/>
</nodes>"""
EDGES = """<edges>
  <edge id="WJ" from="W" to="J" priority="3" numLanes="1" speed="13.89"/>
  <edge id="JE" from="J" to="E" priority="3" numLanes="1" speed="13.89"/>
  <edge id="EJ" from="E" to="J" priority="3" numLanes="1" speed="13.89"/>
  <edge id="JW" from="J" to="W" priority="3" numLanes="1" speed="13.89"/>
  <edge id="SJ" from="S" to="J" priority="1" numLanes="1" speed="13.89"/>
  <edge id="JN" from="J" to="N" priority="1" numLanes="1" speed="13.89"/>
  <edge id="NJ" from="N" to="J" priority="1" numLanes="1" speed="13.89"/>
  <edge id="JS" from="J" to="S" priority="1" numLanes="1" speed="13.89"/>
</edges>"""
LINE_M = 292.8  # [m] netconvert's length of SJ: the yield line's route position
# The same crossroads with two lanes a way and a light at J, held green for N-S
# (:data:`NS_GREEN`; links 0-3 from NJ, 8-11 from SJ: right, straight twice, left): the left
# turn from SJ_1 to JW is a permissive green ``g`` across NJ -> JS, and waits at an internal
# junction 5.01 m past the stop line. SUMO's ``getJunctionFoes`` lists no oncoming foe there.
NS_GREEN = "GGGgrrrrGGGgrrrr"
TWO_LANE_EDGES = EDGES.replace('numLanes="1"', 'numLanes="2"')
TWO_LANE_LINE_M = 289.6  # [m] netconvert's length of SJ with two lanes a way
LIGHT_NODES = NODES.replace(
    'id="J" x="0" y="0" type="priority"', 'id="J" x="0" y="0" type="traffic_light"'
)


@pytest.fixture(scope="module")
def crossroads(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The crossroads above, built by netconvert from plain XML, and a demand with no car
    (the foe is added by the test)."""
    folder = tmp_path_factory.mktemp("crossroads")
    (folder / "empty.rou.xml").write_text(NO_DEMAND)
    return plain_net(folder, "crossroads", NODES, EDGES), folder / "empty.rou.xml"


@pytest.fixture(scope="module")
def left_turn(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The signalised crossroads above and a demand with no car."""
    folder = tmp_path_factory.mktemp("left_turn")
    (folder / "empty.rou.xml").write_text(NO_DEMAND)
    return plain_net(folder, "left_turn", LIGHT_NODES, TWO_LANE_EDGES), folder / "empty.rou.xml"


def test_the_ego_clears_accelerating_hardest_up_to_the_limit() -> None:
    # from a standstill: 3, 6, 9, 12 m/s -> 3, 9, 18, 30 m: 19 m take 4 steps
    assert clear_time_s(19.0, 0.0, 13.89) == 4.0
    # at 13 m/s under 13.89: 13.89 m a step, 30 m take 3 steps
    assert clear_time_s(30.0, 13.0, 13.89) == 3.0
    assert clear_time_s(0.0, 0.0, 13.89) == 0.0
    assert clear_time_s(5.0, 0.0, 0.0) == math.inf  # a zero limit never clears


def test_a_foe_arrives_as_early_as_its_acceleration_allows() -> None:
    # 10 m/s, 2 m/s^2 up to 14 m/s: 2 s and 24 m to 14 m/s, then 76 m at 14 m/s in 5.43 s
    assert arrival_time_s(100.0, 10.0, 2.0, 14.0) == pytest.approx(2.0 + 76.0 / 14.0)
    assert arrival_time_s(9.0, 0.0, 2.0, 14.0) == pytest.approx(3.0)  # 9 = 2 t^2 / 2
    assert arrival_time_s(50.0, 10.0, 0.0, 14.0) == pytest.approx(5.0)  # no acceleration
    assert arrival_time_s(50.0, 0.0, 0.0, 14.0) == math.inf  # standing, cannot start
    assert arrival_time_s(-1.0, 0.0, 2.0, 14.0) == 0.0  # already in the conflict


def test_link_states_and_junction_ids() -> None:
    # priority, then open but yielding, then the light's to judge (red, red-yellow, yellow)
    assert [link_yields(c) for c in "GMOgmsw=oZruy"] == [False] * 3 + [True] * 7 + [False] * 3
    assert junction_of(":J_7_0") == "J"
    assert junction_of(":cluster_J1_J2_12_0") == "cluster_J1_J2"
    assert junction_of("SJ_0") == ""


def test_foes_are_looked_for_up_to_the_last_yielding_link_before_an_unregulated_one() -> None:
    junctions = [("A", 50.0, 60.0), ("B", 120.0, 132.0), ("U", 150.0, 159.0),
                 ("C", 180.0, 191.0)]  # fmt: skip
    sensor = YieldSensor(junctions, 5.0, unregulated=frozenset({"U"}))
    links = [("x", True, True, False, f":{j}_0_0", state, "s", length)
             for j, state, length in (("A", "M", 10.0), ("B", "m", 12.0), ("U", "M", 9.0),
                                      ("C", "m", 11.0))]  # fmt: skip
    # from 20 m: B's line 100 m ahead and its 12 m link, and a metre; C lies beyond U
    assert sensor.horizon(links, 20.0) == ({"B": "m"}, 100.0 + 12.0 + 1.0)
    # from 160 m, past U: C's line 20 m ahead
    assert sensor.horizon(links, 160.0) == ({"C": "m"}, 20.0 + 11.0 + 1.0)
    assert sensor.horizon(links[:1], 20.0) == ({}, 0.0)  # nothing yields: no look-up


def test_foes_are_looked_for_in_a_junction_entered_by_a_yielding_link() -> None:
    junctions = [("A", 50.0, 60.0), ("B", 120.0, 132.0), ("U", 150.0, 159.0)]
    sensor = YieldSensor(junctions, 5.0, unregulated=frozenset({"U"}))
    links = [("x", True, True, False, f":{j}_0_0", state, "s", length)
             for j, state, length in (("A", "M", 10.0), ("B", "m", 12.0),
                                      ("U", "M", 9.0))]  # fmt: skip
    assert sensor.horizon(links, 40.0) == ({"B": "m"}, 80.0 + 12.0 + 1.0)
    # past B's line, inside B (its link read as "m" before the line): to its end at 132 m
    # and a metre; U lies beyond
    assert sensor.horizon(links[2:], 125.0) == ({"B": "m"}, 132.0 - 125.0 + 1.0)
    # inside A, whose link had priority: nothing to look for there
    assert sensor.horizon(links[1:], 55.0) == ({"B": "m"}, 65.0 + 12.0 + 1.0)
    assert sensor.passing(55.0) is None
    assert sensor.passing(132.0) is None  # on the edge out of B


def _foe(foe_dist_m: float, foe_exit_m: float, ego_exit_m: float = 14.0) -> JunctionFoe:
    return JunctionFoe("foe", ego_exit_m - 3.2, foe_dist_m, ego_exit_m, foe_exit_m,
                       ":J_7_0", ":J_10_0", True, False)  # fmt: skip


def test_the_ego_yields_when_the_foe_arrives_before_it_has_cleared_plus_the_margin() -> None:
    cruising = FoeMotion(13.89, 2.6, 13.89, 5.0)
    # the ego stands 5 m before the line: its back leaves the conflict 14 + 5 = 19 m on,
    # in 4 steps; the foe at 13.89 m/s arrives in d / 13.89 s
    ego = (0.0, 13.89, 5.0)
    yield_within_s = 4.0 + YIELD_MARGIN_S  # 6 s
    near = _foe(13.89 * yield_within_s - 1.0, 13.89 * yield_within_s + 2.2)
    far = _foe(13.89 * yield_within_s + 1.0, 13.89 * yield_within_s + 4.2)
    assert must_yield("m", near, cruising, *ego)
    assert not must_yield("m", far, cruising, *ego)
    assert not must_yield("M", near, cruising, *ego)  # the ego's link has priority
    assert not must_yield("G", near, cruising, *ego)
    assert must_yield("g", near, cruising, *ego)  # a permissive turn at a light
    passed = _foe(-9.0, -4.0)  # its front 4 m past the conflict, its back 1 m in it
    gone = _foe(-11.0, -6.0)  # its back 1 m past it
    assert not must_yield("m", gone, cruising, *ego)
    # the ego, standing 10.8 m before the conflict, reaches it in 3 steps (3 + 6 + 9 m):
    # at 13.89 m/s the foe's back leaves in 1 / 13.89 = 0.07 s, 0.07 + 2 < 3: no need to wait
    assert not must_yield("m", passed, cruising, *ego)
    # at 0.3 m/s it leaves in 1 / 0.3 = 3.3 s, 3.3 + 2 > 3: wait; standing, it never leaves
    assert must_yield("m", passed, dataclasses.replace(cruising, speed_mps=0.3), *ego)
    assert must_yield("m", passed, dataclasses.replace(cruising, speed_mps=0.0), *ego)
    at_red = FoeMotion(13.89, 2.6, 13.89, 5.0, link_state="r")
    assert not must_yield("m", near, at_red, *ego)
    not_responding = near._replace(ego_responds=False)
    assert not must_yield("m", not_responding, cruising, *ego)


def _conflict(ego_dist_m: float, foe_dist_m: float, foe_exit_m: float) -> JunctionFoe:
    """A conflict area 6 m long on the ego's way (its end 6 m after its start)."""
    return JunctionFoe("foe", ego_dist_m, foe_dist_m, ego_dist_m + 6.0, foe_exit_m,
                       ":J_7_0", ":J_10_0", True, False)  # fmt: skip


def test_a_foe_keeping_its_speed_reaches_and_leaves_the_conflict() -> None:
    at_12 = FoeMotion(12.0, 2.6, 13.89, 5.0)
    # 48 m to the area, 54 m to its end and 5 m of car: in at 48 / 12 = 4 s, out at 59 / 12
    assert foe_window_s(_conflict(2.0, 48.0, 54.0), at_12) == (4.0, 59.0 / 12.0)
    assert foe_window_s(_conflict(2.0, -1.0, 5.0), at_12) == (0.0, 10.0 / 12.0)  # inside
    assert foe_window_s(_conflict(2.0, -12.0, -6.0), at_12) == (0.0, 0.0)  # gone
    standing = dataclasses.replace(at_12, speed_mps=0.05)
    assert foe_window_s(_conflict(2.0, 3.0, 9.0), standing) == (math.inf, math.inf)
    assert foe_window_s(_conflict(2.0, -1.0, 5.0), standing) == (0.0, math.inf)


def test_entering_the_conflict_in_front_of_a_foe_with_priority_is_a_violation() -> None:
    at_12 = FoeMotion(12.0, 2.6, 13.89, 5.0)
    # the ego's front, 2 m before the area, travels 4 m this step (4 m/s): it enters at
    # 2 / 4 = 0.5 s, and its back (5 m) leaves the 6 m area at (2 + 6 + 5) / 4 = 3.25 s;
    # a foe at 12 m/s breaks the 1 s gap if it arrives before 4.25 s: from under 51 m
    assert YIELD_JUDGE_GAP_S == 1.0
    assert enters_in_front(_conflict(2.0, 50.0, 56.0), at_12, 4.0, 5.0)  # 4.17 s
    assert not enters_in_front(_conflict(2.0, 52.0, 58.0), at_12, 4.0, 5.0)  # 4.33 s
    # no entry this step: still 0.1 m short of the area, or already in it before the step
    assert not enters_in_front(_conflict(2.0, 50.0, 56.0), at_12, 1.9, 5.0)
    assert not enters_in_front(_conflict(0.0, 50.0, 56.0), at_12, 4.0, 5.0)
    # a foe inside, its back out at 9 / 12 = 0.75 s, after the ego's entry at 0.5 s
    assert enters_in_front(_conflict(2.0, -1.0, 4.0), at_12, 4.0, 5.0)
    # its back out at 4 / 12 = 0.33 s, before the ego's entry: it has left
    assert not enters_in_front(_conflict(2.0, -6.0, -1.0), at_12, 4.0, 5.0)
    # standing before the area, it does not count; standing inside, it does
    standing = dataclasses.replace(at_12, speed_mps=0.0)
    assert not enters_in_front(_conflict(2.0, 3.0, 9.0), standing, 4.0, 5.0)
    assert enters_in_front(_conflict(2.0, -1.0, 4.0), standing, 4.0, 5.0)
    # a foe at red, or one the ego's link need not yield to
    at_red = dataclasses.replace(at_12, link_state="r")
    assert not enters_in_front(_conflict(2.0, 50.0, 56.0), at_red, 4.0, 5.0)
    no_priority = _conflict(2.0, 50.0, 56.0)._replace(ego_responds=False)
    assert not enters_in_front(no_priority, at_12, 4.0, 5.0)


def test_an_ego_driving_off_from_a_wait_is_judged_clearing_as_it_accelerates() -> None:
    at_12 = FoeMotion(12.0, 2.6, 13.89, 5.0)
    # as above, 13 m to clear at 4 m/s: 3.25 s, with the gap 4.25 s; a foe 40 m away
    # arrives at 3.33 s: a violation at a held speed
    assert enters_in_front(_conflict(2.0, 40.0, 46.0), at_12, 4.0, 5.0)
    # accelerating at 2 m/s^2: 4 t + t^2 = 13, t = sqrt(17) - 2 = 2.12 s, with the gap
    # 3.12 s: the foe at 40 m (3.33 s) is none, one at 36 m (3.0 s) is one
    assert not enters_in_front(_conflict(2.0, 40.0, 46.0), at_12, 4.0, 5.0, 2.0)
    assert enters_in_front(_conflict(2.0, 36.0, 42.0), at_12, 4.0, 5.0, 2.0)
    # at most SUMO's default 2.6 m/s^2: 4 t + 1.3 t^2 = 13, t = 1.98 s, with the gap 2.98 s
    assert not enters_in_front(_conflict(2.0, 36.0, 42.0), at_12, 4.0, 5.0, 5.0)
    assert enters_in_front(_conflict(2.0, 35.0, 41.0), at_12, 4.0, 5.0, 5.0)  # 2.92 s
    # braking is judged as a held speed
    assert enters_in_front(_conflict(2.0, 40.0, 46.0), at_12, 4.0, 5.0, -3.0)


def _drive(
    env: UrbanDriveEnv,
    foe_at_step: int,
    steps: int = 70,
    foe_route: tuple[str, str] = ("WJ", "JE"),
    light: str = "",
    foe_lane: str = "first",
) -> list[dict[str, float]]:
    """Drive the ego by the shield, asking for the fastest change (a SUMO baseline ego drives
    itself); a foe enters ``foe_route`` (the priority road) at its start, on ``foe_lane``, at
    13.89 m/s, after ``foe_at_step`` steps; J's light, if it has one, is held at the state
    ``light``. One row a step; the last one's ``t`` is the arrival time [s]."""
    obs, info = env.reset(seed=0)
    api = env.sumo
    api.route.add("major", list(foe_route))
    if light:
        api.trafficlight.setRedYellowGreenState("J", light)
    rows = []
    for i in range(steps):
        if i == foe_at_step:
            api.vehicle.add("foe", "major", departPos="0", departSpeed="13.89",
                            departLane=foe_lane)  # fmt: skip
        seen = env._episode().seen
        assert seen is not None
        foe_road = api.vehicle.getRoadID("foe") if "foe" in api.vehicle.getIDList() else ""
        rows.append({"pos": env.route_pos_m, "v": float(obs[S.V_EGO]),
                     "lead": float(obs[S.D_LEAD]), "dv": float(obs[S.DV]),
                     "yield": seen.yields.leader_gap_m, "info_yield": info["yield_gap_m"],
                     "foe_out": foe_road == foe_route[1],
                     "foe_gone": foe_road in (foe_route[1], ""),
                     "yield_violation": False})  # fmt: skip
        decision = shield(obs, np.arange(7, dtype=np.float64))  # the fastest safe change
        obs, _r, terminated, truncated, info = env.step(decision.action)
        assert not info["collision"]
        rows[-1]["yield_violation"] = info["yield_violation"]
        if terminated or truncated:
            break
    assert info["arrived"]
    rows[-1]["t"] = info["time_s"]
    return rows


@pytest.mark.slow
def test_a_yield_line_holds_the_ego_while_a_foe_with_priority_approaches(
    make_env: Callable[..., UrbanDriveEnv], crossroads: tuple[Path, Path]
) -> None:
    net, demand = crossroads
    env = make_env(net_file=net, route=("SJ", "JN"), demand_file=demand, warmup_s=0,
                   max_steps=70)  # fmt: skip
    # the ego reaches the line after about 23 s; the foe, entering after 3 s, after 24 s
    rows = _drive(env, foe_at_step=3)
    held = [r for r in rows if r["yield"] < S.SENSOR_RANGE_M]
    assert held, "the yield line was never a leader"
    assert all(r["info_yield"] == r["yield"] for r in rows)  # info gives what was perceived
    for r in held:  # a standing virtual leader at the line: gap to the line, dv = own speed
        assert r["yield"] == pytest.approx(LINE_M - r["pos"], abs=1e-6)
        assert r["lead"] == pytest.approx(LINE_M - r["pos"], abs=1e-3)
        assert r["dv"] == pytest.approx(r["v"], abs=1e-6)
    # the ego's front crosses the line only once the foe has left the junction
    first_past = next(r for r in rows if r["pos"] > LINE_M)
    assert first_past["foe_out"]
    assert min(LINE_M - r["pos"] for r in rows if r["pos"] <= LINE_M) > 0.0
    # once the foe has passed, the line is no leader
    assert all(r["yield"] == S.SENSOR_RANGE_M for r in rows if r["foe_gone"])
    assert not any(r["yield_violation"] for r in rows)


@pytest.mark.slow
def test_entering_in_front_of_the_foe_is_a_yield_violation(
    make_env: Callable[..., UrbanDriveEnv], crossroads: tuple[Path, Path]
) -> None:
    net, demand = crossroads
    env = make_env(net_file=net, route=("SJ", "JN"), demand_file=demand, warmup_s=0,
                   max_steps=40)  # fmt: skip
    obs, _ = env.reset(seed=0)
    env.sumo.route.add("major", ["WJ", "JE"])
    flagged = []
    for i in range(40):
        if i == 3:  # as above: the foe reaches J about 24 s in
            env.sumo.vehicle.add("foe", "major", departPos="0", departSpeed="13.89")
        # no shield: 3, 6, 9, 12 m/s, then 13 m/s, whatever lies ahead
        before = env.route_pos_m
        change = int(np.clip(13 - round(float(obs[S.V_EGO])), -3, 3))
        obs, _r, terminated, truncated, info = env.step(change + 3)
        if info["yield_violation"]:
            flagged.append((before, env.route_pos_m))
        if terminated or truncated:
            break
    # 35.1 m after 4 steps, then 13 m a step: the line at 292.8 m is crossed in the step
    # from 282.1 m to 295.1 m; the conflict area with the foe's lane starts 4 m past it and
    # is 3.2 m long (SUMO's distances), and is entered in the next step, to 308.1 m: 1.7 m
    # into the step's 13 m, the ego's back out (1.7 + 3.2 + 5) / 13 = 0.76 s after the
    # step's start, the foe, 20.1 m away at 14.3 m/s, in at 1.40 s: within 1 s
    assert flagged == [(pytest.approx(295.1), pytest.approx(308.1))]


@pytest.mark.slow
def test_a_far_foe_makes_no_yield_line(
    make_env: Callable[..., UrbanDriveEnv], crossroads: tuple[Path, Path]
) -> None:
    net, demand = crossroads
    env = make_env(net_file=net, route=("SJ", "JN"), demand_file=demand, warmup_s=0,
                   max_steps=70)  # fmt: skip
    # entering after 14 s, the foe reaches J about 35 s in, 10 s after the ego has crossed
    rows = _drive(env, foe_at_step=14)
    assert all(r["yield"] == S.SENSOR_RANGE_M for r in rows)
    assert all(r["lead"] == S.SENSOR_RANGE_M for r in rows)


@pytest.mark.slow
def test_the_shielded_ego_yields_as_sumo_krauss_does(
    make_env: Callable[..., UrbanDriveEnv], crossroads: tuple[Path, Path]
) -> None:
    net, demand = crossroads
    times = {}
    for model in ("krauss", "agent"):
        env = make_env(net_file=net, route=("SJ", "JN"), demand_file=demand, warmup_s=0,
                       max_steps=70, ego_model=model)  # fmt: skip
        rows = _drive(env, foe_at_step=3)
        assert next(r for r in rows if r["pos"] > LINE_M)["foe_out"]  # after the foe
        times[model] = rows[-1]["t"]
    # measured: both arrive 52 s after entering (48 s with the rule off: the ego crosses
    # before the foe, which brakes for it)
    assert times["agent"] == pytest.approx(times["krauss"], abs=2.0)


def test_where_two_lanes_cross_along_each() -> None:
    assert crossing_offsets([(0, 0), (0, 10)], [(-5, 4), (5, 4)]) == (4.0, 5.0)
    # a left turn: 4 m ahead, then 10 m to the left; a way down across it 3 m to the left
    turn = [(0.0, 0.0), (0.0, 4.0), (-10.0, 4.0)]
    assert crossing_offsets(turn, [(-3, 10), (-3, -10)]) == (4.0 + 3.0, 6.0)
    # a way merging into the turn's end meets it there: 14 m along the turn, 9.22 m along it
    merge = crossing_offsets(turn, [(-3, 10), (-10, 4)])
    assert merge == (pytest.approx(14.0), pytest.approx(math.hypot(7.0, 6.0)))
    assert crossing_offsets(turn, [(5, 0), (5, 10)]) is None


def test_a_foe_at_the_internal_junction_of_a_turn_meets_it_where_their_lanes_cross() -> None:
    # the lanes cross 7 m along the ego's way from its line and 6 m along the foe's via
    # lane; the ego 20 m before its line, the foe 30 m before its via lane: the area is
    # 2.5 m either side of 27 m and of 36 m
    assert CONFLICT_HALF_M == 2.5
    foe = turn_foe("foe", ":J_1_0", 6.0, 7.0, 30.0, 20.0, ":J_14_0")
    assert foe == JunctionFoe("foe", 24.5, 33.5, 29.5, 38.5, ":J_14_0", ":J_1_0", True, False,
                              True)  # fmt: skip
    assert junction_of(foe.ego_lane) == "J"


_LINKS = {":J_8_0": [("JW_0", False, True, False, ":J_14_0", "m", "l", 10.0)],
          ":J_7_0": [("JN_0", True, True, False, "", "M", "s", 0.0)],
          "NJ_0": [("JW_0", True, True, False, ":J_0_0", "G", "r", 9.22),
                   ("JS_0", True, True, False, ":J_1_0", "G", "s", 20.0),
                   ("JE_0", False, True, False, ":J_2_0", "g", "l", 4.0)]}  # fmt: skip
_SHAPES = {":J_8_0": [(0.0, 0.0), (0.0, 4.0)], ":J_14_0": [(0.0, 4.0), (-10.0, 4.0)],
           ":J_0_0": [(-3.0, 10.0), (-10.0, 4.0)],
           ":J_1_0": [(-3.0, 10.0), (-3.0, -10.0)]}  # fmt: skip
# ``lane`` of a network with the left turn of the test above: its foes are NJ_0's links
# (two of them) and a walking area; NJ's right turn and straight cross the lane after the
# internal junction, its left turn does not
_LANE_API = SimpleNamespace(
    getLinks=lambda lane: _LINKS.get(lane, []),
    getLength=lambda lane: 4.0,
    getShape=lambda lane: _SHAPES[lane],
    getFoes=lambda lane, to: ("NJ_0", "NJ_0", ":J_w0_0"),
    getInternalFoes=lambda lane: (
        (":J_0_0", ":J_1_0", ":J_7_0") if lane == ":J_14_0" else (":J_1_0",)
    ),
)


def test_the_foes_of_a_turn_are_the_links_with_priority_crossing_its_way() -> None:
    api = SimpleNamespace(lane=_LANE_API)
    assert turn_geometry(api, ":J_8_0") == TurnGeometry(
        4.0, ":J_14_0",
        (("NJ_0", ":J_0_0", pytest.approx(math.hypot(7.0, 6.0)), pytest.approx(14.0)),
         ("NJ_0", ":J_1_0", 6.0, 7.0)),
    )  # fmt: skip
    assert turn_geometry(api, ":J_7_0") is None  # straight on: no internal junction


def test_the_judge_lets_a_turning_ego_accelerate_out_of_the_conflict() -> None:
    at_10 = FoeMotion(10.0, 2.6, 13.89, 5.0)
    # the ego 1 m before a 5 m area at 2 m/s, 5 m long: at that speed its back leaves after
    # 11 / 2 = 5.5 s; accelerating at 2.6 m/s^2 from its wait at the internal junction,
    # 2 t + 1.3 t^2 = 11 gives 2.24 s. A foe at 10 m/s 40 m away arrives at 4 s.
    crossing = JunctionFoe("foe", 1.0, 40.0, 6.0, 45.0, ":J_14_0", ":J_1_0", True, False)
    assert enters_in_front(crossing, at_10, 2.0, 5.0)  # 4 < 5.5 + 1
    assert not enters_in_front(crossing._replace(turning=True), at_10, 2.0, 5.0)  # 4 > 3.24
    # 30 m away it arrives at 3 s < 2.24 + 1
    near = crossing._replace(foe_dist_m=30.0, foe_exit_m=35.0, turning=True)
    assert enters_in_front(near, at_10, 2.0, 5.0)


@pytest.mark.slow
def test_a_permissive_left_turn_waits_inside_the_junction_for_an_oncoming_car(
    make_env: Callable[..., UrbanDriveEnv], left_turn: tuple[Path, Path]
) -> None:
    net, demand = left_turn
    env = make_env(net_file=net, route=("SJ", "JW"), demand_file=demand, warmup_s=0,
                   max_steps=70)  # fmt: skip
    # the ego, turning left on the permissive green, reaches the line after about 23 s; the
    # oncoming foe (NJ -> JS), entering after 3 s, reaches J after about 24 s
    rows = _drive(env, foe_at_step=3, foe_route=("NJ", "JS"), light=NS_GREEN, foe_lane="1")
    held = [r for r in rows if r["yield"] < S.SENSOR_RANGE_M]
    assert held, "the yield line was never a leader"
    # the virtual leader stands where SUMO's drivers wait, at the internal junction 5.01 m
    # past the stop line (the conflict area starts later: 9.91 - 2.5 = 7.41 m past it)
    for r in held:
        assert r["yield"] == pytest.approx(TWO_LANE_LINE_M + 5.01 - r["pos"], abs=0.01)
        assert r["lead"] == pytest.approx(TWO_LANE_LINE_M + 5.01 - r["pos"], abs=0.01)
    # the ego's front passes the internal junction only once the foe is out of the junction
    assert next(r for r in rows if r["pos"] > TWO_LANE_LINE_M + 5.01)["foe_out"]
    assert all(r["yield"] == S.SENSOR_RANGE_M for r in rows if r["foe_gone"])
    assert not any(r["yield_violation"] for r in rows)  # and _drive checks: no collision


@pytest.mark.slow
def test_turning_left_in_front_of_an_oncoming_car_is_a_yield_violation(
    make_env: Callable[..., UrbanDriveEnv], left_turn: tuple[Path, Path]
) -> None:
    net, demand = left_turn
    env = make_env(net_file=net, route=("SJ", "JW"), demand_file=demand, warmup_s=0,
                   max_steps=40)  # fmt: skip
    obs, _ = env.reset(seed=0)
    api = env.sumo
    api.route.add("major", ["NJ", "JS"])
    api.trafficlight.setRedYellowGreenState("J", NS_GREEN)
    flagged = []
    for i in range(40):
        if i == 3:
            api.vehicle.add("foe", "major", departPos="0", departSpeed="13.89", departLane="1")
        before = env.route_pos_m
        foe_to_j = api.lane.getLength("NJ_1") - api.vehicle.getLanePosition("foe") if i > 3 else 0
        change = int(np.clip(13 - round(float(obs[S.V_EGO])), -3, 3))  # no shield
        obs, _r, terminated, truncated, info = env.step(change + 3)
        if info["yield_violation"]:
            flagged.append((before, env.route_pos_m, foe_to_j))
        if terminated or truncated:
            break
    # 13 m a step from 4 steps on. The ego's way (its 5.01 m via lane, then the lane after its
    # internal junction) crosses the centre line of NJ_1's straight via lane 9.91 m past the
    # stop line at 289.6 m, 11.68 m along that via lane; the area is 2.5 m either side. The
    # step from 295.1 m to 308.1 m enters it 289.6 + 9.91 - 2.5 - 295.1 = 1.91 m in, at 0.15 s;
    # driving on at 2.6 m/s^2 from 13 m/s, the ego's back leaves it 5 + 5 + 1.91 = 11.91 m on,
    # at 0.85 s (13 t + 1.3 t^2 = 11.91); the foe, 12.1 m before its via lane at 13.89 m/s,
    # arrives (12.1 + 11.68 - 2.5) / 13.89 = 1.53 s after the step's start, within 1 s
    assert flagged == [(pytest.approx(295.1), pytest.approx(308.1), pytest.approx(12.1, abs=0.1))]
