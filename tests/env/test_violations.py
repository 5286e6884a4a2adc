"""The violation judge against a fake simulation."""

from __future__ import annotations

from explaindrive.env.perception import CrossingSensor, SignalLink
from explaindrive.env.right_of_way import Conflict, FoeMotion, JunctionFoe
from explaindrive.env.violations import ViolationJudge, Violations, ego_collided, speeding
from explaindrive.sim.route import RouteGeometry, RouteJunction
from tests.env.fake_sumo import FakeSumo
from tests.env.test_perception import LANE, ZEBRA

# the ego's links before the step: J1's 5 m ahead (index 2), then a joined cluster C whose
# two stop lines lie 9 m and 12 m ahead (indices 6 and 16)
LINKS = (SignalLink("J1", 2, 5.0, "G"), SignalLink("C", 6, 9.0, "G"),
         SignalLink("C", 16, 12.0, "G"))  # fmt: skip


# the route's junctions: a light at 100-112 m, the zebra's at 250-262 m, a priority
# junction at 400-410 m
JUNCTIONS = (
    RouteJunction("J1", 100.0, 112.0, signalized=True, crossing=False),
    RouteJunction("Z", 250.0, 262.0, signalized=False, crossing=True),
    RouteJunction("P", 400.0, 410.0, signalized=False, crossing=False),
)
EGO_LENGTH_M = 5.0  # [m]
GEOMETRY = RouteGeometry(("a", "b"), (0.0, 112.0), 600.0, (0.0,), (13.89,), (), (ZEBRA,),
                         JUNCTIONS)  # fmt: skip


def judge() -> ViolationJudge:
    return ViolationJudge(CrossingSensor((ZEBRA,), {":Z_c0": LANE}), GEOMETRY, EGO_LENGTH_M)


def test_crossing_a_red_stop_line_is_a_run_and_a_green_one_is_not() -> None:
    # the colours after the step: J1's link 2 red, link 3 green
    red, green = FakeSumo(lights={"J1": "GGrG"}), FakeSumo(lights={"J1": "rrGr"})
    assert judge().ran_red_light(red, LINKS[:1], 5.0)  # the line 5 m ahead is crossed
    assert not judge().ran_red_light(red, LINKS[:1], 4.9)  # still before it
    assert not judge().ran_red_light(red, (SignalLink("J1", 2, 0.0, "r"),), 3.0)  # on it
    assert not judge().ran_red_light(green, LINKS[:1], 6.0)
    # the link read is the ego's own: link 3 of J1 is red in ``green``, but not the ego's
    assert not judge().ran_red_light(green, (SignalLink("J1", 2, 5.0, "G"),), 6.0)
    assert judge()(red, 95.0, 101.0, LINKS[:1], {}) == Violations(True, False, "signal")


def test_each_stop_line_of_a_joined_cluster_is_judged_on_its_own_link() -> None:
    # programme C: link 6 (its first stop line) green, link 16 (its second) red
    api = FakeSumo(lights={"J1": "GGGG", "C": "G" * 6 + "G" + "G" * 9 + "r"})
    assert not judge().ran_red_light(api, LINKS, 9.0)  # across J1 and C's first line only
    assert judge().ran_red_light(api, LINKS, 12.0)  # and C's second, at red, in one step
    assert not judge().ran_red_light(api, LINKS[2:], 11.9)


def test_crossing_into_a_pedestrian_in_the_lane_is_a_yield_violation() -> None:
    people = {"p": (4.0, 0.0, 90.0, 1.2, ":Z_c0")}
    empty, busy = FakeSumo(people=people), FakeSumo(persons={":Z_c0": ("p",)}, people=people)
    assert judge().crossed_occupied(empty, 245.0, 252.0, {":Z_c0": True})  # seen before
    assert judge().crossed_occupied(busy, 245.0, 252.0, {})  # in the lane after the step
    assert not judge().crossed_occupied(empty, 245.0, 252.0, {":Z_c0": False})
    assert not judge().crossed_occupied(busy, 251.0, 258.0, {":Z_c0": True})  # line behind


def test_each_step_has_the_site_of_its_violations_or_of_the_ego() -> None:
    people = {"p": (4.0, 0.0, 90.0, 1.2, ":Z_c0")}
    empty = FakeSumo(lights={"J1": "GGGG"}, people=people)
    steps = ((90.0, 99.9), (95.0, 100.0), (111.0, 112.0), (240.0, 255.0), (400.0, 409.9))
    site = [judge()(empty, prev, pos, (), {}).site for prev, pos in steps]
    assert site == ["free_road", "signal", "free_road", "crossing", "yield_junction"]
    # a red-light run counts at its signal, a pedestrian-yield violation at its crossing,
    # wherever the ego's front ends the step
    red = FakeSumo(lights={"J1": "GGrG"})
    assert judge()(red, 95.0, 115.0, LINKS[:1], {}) == Violations(True, False, "signal")
    ped = judge()(empty, 245.0, 265.0, (), {":Z_c0": True})
    assert ped == Violations(False, True, "crossing")


def test_entering_a_conflict_area_in_front_of_a_foe_is_a_yield_violation() -> None:
    # at P, a conflict area 2 m past the ego's front before the step and 6 m long; the foe
    # at 12 m/s, 50 m from it: the ego entering at 4 m/s clears it (with its 5 m) at
    # 13 / 4 = 3.25 s, the foe arrives at 50 / 12 = 4.17 s, within 1 s of it
    foe = JunctionFoe("car", 2.0, 50.0, 8.0, 56.0, ":P_1_0", ":P_4_0", True, False)
    conflict = Conflict(foe, FoeMotion(12.0, 2.6, 13.89, 5.0))
    api = FakeSumo()
    step = judge()(api, 396.0, 400.0, (), {}, (conflict,))
    assert step == Violations(False, False, "yield_junction", yield_violation=True)
    # 1.9 m: the front stops short of the area
    assert not judge()(api, 396.0, 397.9, (), {}, (conflict,)).yield_violation
    # the foe 60 m away arrives at 5 s, 1.75 s after the ego has left
    far = Conflict(foe._replace(foe_dist_m=60.0, foe_exit_m=66.0), conflict.motion)
    assert not judge()(api, 396.0, 400.0, (), {}, (far,)).yield_violation


def test_the_judge_reads_the_egos_acceleration_from_its_travel_step_to_step() -> None:
    # the conflict 2 m ahead, the foe at 12 m/s 40 m from it (arrives at 3.33 s); the ego
    # enters at 4 m/s and must clear 13 m: at a held speed 3.25 s + 1 s gap, a violation
    foe = JunctionFoe("car", 2.0, 40.0, 8.0, 46.0, ":P_1_0", ":P_4_0", True, False)
    conflict = Conflict(foe, FoeMotion(12.0, 2.6, 13.89, 5.0))
    api = FakeSumo()
    assert judge()(api, 396.0, 400.0, (), {}, (conflict,)).yield_violation
    # after a step of 2 m, the 4 m step drove off at 2 m/s^2: 4 t + t^2 = 13 gives 2.12 s,
    # with the gap 3.12 s, before the foe
    driving_off = judge()
    assert not driving_off(api, 394.0, 396.0, (), {}).yield_violation
    assert not driving_off(api, 396.0, 400.0, (), {}, (conflict,)).yield_violation


def test_collisions_and_speeding() -> None:
    assert ego_collided(FakeSumo(collisions=(("car", "ego"),)))
    assert not ego_collided(FakeSumo(collisions=(("car", "bus"),)))
    assert speeding(13.9, 13.89) and not speeding(13.89, 13.89)
