"""The check of an explanation against the state, at a junction where the car gives way."""

from __future__ import annotations

from typing import Any

from explaindrive.language.explanation.explainer import Factor, check_grounding, mentioned_factors
from explaindrive.language.explanation.grounding import reply_problems
from explaindrive.language.explanation.summary import StateRecord

GIVING_WAY = "We're giving way at the junction 12 m ahead: a car with priority is coming."


def rec(action: int, **state: Any) -> StateRecord:
    base: dict[str, Any] = {"v_ego": 6.0, "v_lim": 13.9}
    base.update(state)
    return StateRecord.model_validate({"request": "fast", "action": action, "state": base})


def test_giving_way_is_accepted_with_a_yield_line_in_the_state() -> None:
    assert mentioned_factors(GIVING_WAY) == {Factor.GIVE_WAY}
    assert check_grounding(GIVING_WAY, Factor.GIVE_WAY, rec(-2, d_yield=12.0)).ok
    assert reply_problems(GIVING_WAY, rec(-2, d_yield=12.0), Factor.GIVE_WAY) == []
    # 14.6 m is within max(3 m, 20 %) of 12 m; 16 m is not
    assert reply_problems(GIVING_WAY, rec(-2, d_yield=14.6), Factor.GIVE_WAY) == []
    assert reply_problems(GIVING_WAY, rec(-2, d_yield=16.0), Factor.GIVE_WAY) == [
        "gives a distance of 12 m; the state has 16 m"
    ]


def test_giving_way_is_rejected_without_a_yield_line() -> None:
    # the old reading of the same step: the line as a standing car 12 m ahead
    car = rec(-2, d_lead=12.0, dv=6.0)
    g = check_grounding(GIVING_WAY, Factor.LEAD_VEHICLE, car)
    assert not g.ok and g.absent == (Factor.GIVE_WAY,) and not g.names_factor
    assert reply_problems(GIVING_WAY, car, Factor.LEAD_VEHICLE) == [
        "does not name the lead vehicle",
        "names factors not in the state: give_way",
        "names hazards the state does not hold: junction",
    ]


def test_a_car_ahead_is_rejected_at_a_yield_line() -> None:
    text = "I'm braking for the car ahead, 12 m away."
    assert reply_problems(text, rec(-2, d_yield=12.0), Factor.GIVE_WAY) == [
        "does not name the give way",
        "names factors not in the state: lead_vehicle",
    ]


def test_a_junction_needs_a_light_or_a_yield_line() -> None:
    light = rec(-2, d_tl=30.0, tl_state="red")
    assert reply_problems("The light at the junction 30 m ahead is red.", light, None) == []
    assert reply_problems("I'm braking before the junction.", rec(-2), None) == [
        "names no factor of the state",
        "names hazards the state does not hold: junction",
    ]


def test_giving_way_to_a_pedestrian_is_the_crossing() -> None:
    text = "I'm braking to give way to a pedestrian on the crossing 20 m ahead."
    assert mentioned_factors(text) == {Factor.PEDESTRIAN}
    assert reply_problems(text, rec(-2, d_cross=20.0), Factor.PEDESTRIAN) == []


def test_stopping_at_the_yield_line_is_true_while_braking_for_it() -> None:
    # 6 m/s braking by 2 m/s ends at 4 m/s: "stopping" is true only for a line ahead
    text = "I'm slowing down to stop and give way at the junction 12 m ahead."
    assert reply_problems(text, rec(-2, d_yield=12.0), Factor.GIVE_WAY) == []
    assert "says stopping while the action is -2 m/s at 6.0 m/s" in reply_problems(
        text, rec(-2, d_tl=12.0, tl_state="green"), None
    )
