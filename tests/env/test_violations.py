"""The violation judge against a fake simulation."""

from __future__ import annotations

from explaindrive.env.perception import CrossingSensor, LightSensor
from explaindrive.env.violations import ViolationJudge, Violations, ego_collided, speeding
from tests.env.fake_sumo import FakeSumo
from tests.env.test_perception import LANE, LIGHTS, ZEBRA


def judge() -> ViolationJudge:
    return ViolationJudge(
        LightSensor(LIGHTS, tls_link={"J1": 0, "J2": 0}), CrossingSensor((ZEBRA,), {":Z_c0": LANE})
    )


def test_crossing_a_red_stop_line_is_a_run_and_a_green_one_is_not() -> None:
    red, green = FakeSumo(lights={"J1": "rGGG"}), FakeSumo(lights={"J1": "GrrG"})
    assert judge().ran_red_light(red, 95.0, 100.0, None)  # the line at 100 m is crossed
    assert not judge().ran_red_light(red, 100.0, 105.0, None)  # already past it
    assert not judge().ran_red_light(red, 90.0, 99.0, None)  # still before it
    assert not judge().ran_red_light(green, 95.0, 101.0, None)
    assert not judge().ran_red_light(red, 95.0, 101.0, "e1_1")  # lane e1_1: link 3, green
    assert judge().ran_red_light(green, 95.0, 101.0, "e1_0")  # lane e1_0: link 2, red
    assert judge()(red, 95.0, 101.0, None, {}) == Violations(True, False)


def test_crossing_into_a_pedestrian_in_the_lane_is_a_yield_violation() -> None:
    people = {"p": (4.0, 0.0, 90.0, 1.2, ":Z_c0")}
    empty, busy = FakeSumo(people=people), FakeSumo(persons={":Z_c0": ("p",)}, people=people)
    assert judge().crossed_occupied(empty, 245.0, 252.0, {":Z_c0": True})  # seen before
    assert judge().crossed_occupied(busy, 245.0, 252.0, {})  # in the lane after the step
    assert not judge().crossed_occupied(empty, 245.0, 252.0, {":Z_c0": False})
    assert not judge().crossed_occupied(busy, 251.0, 258.0, {":Z_c0": True})  # line behind


def test_collisions_and_speeding() -> None:
    assert ego_collided(FakeSumo(collisions=(("car", "ego"),)))
    assert not ego_collided(FakeSumo(collisions=(("car", "bus"),)))
    assert speeding(13.9, 13.89) and not speeding(13.89, 13.89)
