"""The template explainer (LLM-3 embedded) at a junction where the car gives way."""

from __future__ import annotations

from typing import Any

import pytest

from explaindrive.language.explanation.explainer import (
    Factor,
    cause_present,
    mentioned_factors,
    present_factors,
    template_explanation,
)
from explaindrive.language.explanation.grounding import reply_problems
from explaindrive.language.explanation.summary import StateRecord
from tests.language.explanation.records import state_record


def rec(request: str, action: int, **state: Any) -> StateRecord:
    return state_record(request, action, **{"v_ego": 9.0, **state})


def test_a_yield_line_is_a_factor_present_while_it_holds() -> None:
    held = rec("fast", -2, d_yield=12.0).nearby()
    assert present_factors(held) == {Factor.GIVE_WAY, Factor.SPEED_LIMIT}
    assert cause_present(held, Factor.GIVE_WAY)
    # the foe has passed: the line holds the car no more, and no car is ahead either
    gone = rec("fast", 0).nearby()
    assert not cause_present(gone, Factor.GIVE_WAY) and not cause_present(gone, Factor.LEAD_VEHICLE)


def test_the_template_says_the_car_gives_way_at_the_junction() -> None:
    text = template_explanation(rec("fast", 0, v_ego=0.0, d_yield=12.0), Factor.GIVE_WAY)
    assert text == (
        "We're staying put for a moment to give way at the junction 12 m ahead: "
        "a car with priority is coming. We'll go as soon as it has passed."
    )


@pytest.mark.parametrize(
    ("action", "v_ego"), [(-3, 9.0), (-2, 9.0), (-1, 9.0), (0, 9.0), (-3, 2.0)]
)
def test_every_wording_names_the_junction_and_no_car_ahead(action: int, v_ego: float) -> None:
    r = rec("fast", action, v_ego=v_ego, d_yield=12.4)
    text = template_explanation(r, Factor.GIVE_WAY)
    assert "junction 12 m ahead" in text and "priority" in text  # 12.4 m said as 12 m
    assert mentioned_factors(text) == {Factor.GIVE_WAY}
    assert reply_problems(text, r, Factor.GIVE_WAY) == []


def test_harsh_braking_under_comfort_is_apologised_for() -> None:
    text = template_explanation(rec("comfort", -3, d_yield=14.0), Factor.GIVE_WAY)
    assert text.startswith("Sorry, I'm braking") and "junction 14 m ahead" in text


def test_without_a_yield_line_the_template_cannot_name_one() -> None:
    with pytest.raises(ValueError, match="give_way is not in the state"):
        template_explanation(rec("fast", -2, d_lead=12.0, dv=9.0), Factor.GIVE_WAY)
    # beyond the 50 m cut-off it is not in the state either
    with pytest.raises(ValueError, match="not in the state within 50 m"):
        template_explanation(rec("fast", -2, d_yield=51.0), Factor.GIVE_WAY)
