"""The grounded rule engine (LLM-2 embedded) and the template explainer (LLM-3)."""

from __future__ import annotations

from typing import Any

import pytest

from explaindrive.language.backends.embedded import RuleDecider, TemplateExplainer
from explaindrive.language.decision import Conflict, Factor, parse_decision_tag, rule_decision
from explaindrive.language.explanation import check_grounding, mentioned_factors
from explaindrive.language.summary import StateRecord


def rec(request: str, action: int, **state: Any) -> StateRecord:
    base: dict[str, Any] = {"v_ego": 10.0, "v_lim": 13.9}
    base.update(state)
    return StateRecord.model_validate({"request": request, "action": action, "state": base})


def test_fast_braking_for_red_light() -> None:
    d = rule_decision(rec("fast", -2, d_tl=30.0, tl_state="red"))
    assert d.explain and d.factor is Factor.TRAFFIC_LIGHT and d.conflict is Conflict.SLOWS
    assert d.tag == "[EXPLAIN]"


def test_objects_beyond_50_m_are_ignored() -> None:
    d = rule_decision(rec("fast", -2, d_tl=51.0, tl_state="red"))
    assert not d.explain and d.factor is None


def test_priority_pedestrian_then_imminent_leader_then_light() -> None:
    both = rec("fast", -3, d_tl=35.0, tl_state="red", d_cross=20.0, d_lead=8.0, dv=5.0)
    assert rule_decision(both).factor is Factor.PEDESTRIAN
    # leader at 8 m closing at 5 m/s: TTC 1.6 s < 3 s outranks the red light
    assert (
        rule_decision(rec("fast", -2, d_tl=35.0, tl_state="red", d_lead=8.0, dv=5.0)).factor
        is Factor.LEAD_VEHICLE
    )
    # leader at 18 m closing at 1 m/s: headway 1.8 s (< 2 s) but TTC 18 s, light first
    assert (
        rule_decision(rec("fast", -1, d_tl=40.0, tl_state="red", d_lead=18.0, dv=1.0)).factor
        is Factor.TRAFFIC_LIGHT
    )


def test_ordinary_and_supportive_actions_need_no_explanation() -> None:
    assert not rule_decision(rec("fast", 2, d_tl=20.0, tl_state="red")).explain
    assert not rule_decision(rec("comfort", -1, d_tl=20.0, tl_state="red")).explain
    assert not rule_decision(rec("stop", -3, d_lead=5.0, dv=4.0)).explain
    # fast, holding exactly at the limit: ordinary
    assert not rule_decision(rec("fast", 0, v_ego=13.9, d_tl=20.0, tl_state="red")).explain


def test_comfort_harsh_actions() -> None:
    d = rule_decision(rec("comfort", -3, v_ego=12.0, v_lim=8.3))
    assert d.explain and d.factor is Factor.SPEED_LIMIT and d.conflict is Conflict.HARSH_BRAKING
    # yellow at 8 m, 10 m/s: comfortable stop needs 25 m, so accelerating through is explained
    d = rule_decision(rec("comfort", 2, d_tl=8.0, tl_state="yellow"))
    assert d.explain and d.factor is Factor.TRAFFIC_LIGHT
    assert not rule_decision(rec("comfort", 2, v_ego=5.0, d_tl=30.0, tl_state="yellow")).explain


def test_parse_tag() -> None:
    assert parse_decision_tag(" [EXPLAIN]\n") is True
    assert parse_decision_tag("[no explanation needed]") is False
    assert parse_decision_tag("[EXPLAIN] because of the light") is None


@pytest.mark.parametrize("factor", list(Factor))
def test_template_names_only_its_factor(factor: Factor) -> None:
    r = rec("comfort", -3, d_tl=30.0, tl_state="red", d_cross=20.0, d_lead=9.0, dv=2.0)
    e = TemplateExplainer().explain(r, factor)
    assert mentioned_factors(e.text) == {factor}
    assert check_grounding(e.text, factor, r).ok
    assert e.text.count(".") <= 3 and len(e.text) < 220


def test_explainer_distances_and_colour() -> None:
    r = rec("fast", -2, d_tl=34.6, tl_state="yellow")
    d = RuleDecider().decide(r)
    e = TemplateExplainer().explain(r, d.factor)
    assert "35 m" in e.text and "yellow" in e.text
    with pytest.raises(ValueError, match="not in the state"):
        TemplateExplainer().explain(r, Factor.PEDESTRIAN)


def test_grounding_flags_absent_factor() -> None:
    r = rec("fast", -2, d_tl=30.0, tl_state="red")
    g = check_grounding("Slowing for the pedestrian ahead.", Factor.TRAFFIC_LIGHT, r)
    assert not g.ok and g.absent == (Factor.PEDESTRIAN,) and not g.names_factor
