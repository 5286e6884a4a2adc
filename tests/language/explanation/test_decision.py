"""The grounded rule engine (LLM-2 embedded) and the template explainer (LLM-3)."""

from __future__ import annotations

from typing import Any

import pytest

from explaindrive.language.backends.embedded import RuleDecider, TemplateExplainer
from explaindrive.language.explanation.decision import (
    Conflict,
    Factor,
    holding_factors,
    parse_decision_tag,
    rule_decision,
)
from explaindrive.language.explanation.explainer import (
    check_grounding,
    mentioned_factors,
    present_factors,
    template_explanation,
)
from explaindrive.language.explanation.grounding import reply_problems, wording_problems
from explaindrive.language.explanation.hazards import braking_hazards
from explaindrive.language.explanation.summary import StateRecord
from tests.language.explanation.records import state_record as rec


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
    r = rec(
        "comfort", -3, d_tl=30.0, tl_state="red", d_cross=20.0, d_lead=9.0, dv=2.0, d_yield=14.0
    )
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
        template_explanation(r, Factor.PEDESTRIAN)
    # the explainer never raises: a factor the state lacks gives a sentence naming none
    n = TemplateExplainer().explain(r, Factor.PEDESTRIAN)
    assert n.factor is None and mentioned_factors(n.text) == set()
    assert n.text.startswith(("I'm braking", "I'm slowing us down firmly", "I had to brake"))


def test_grounding_flags_absent_factor() -> None:
    r = rec("fast", -2, d_tl=30.0, tl_state="red")
    g = check_grounding("Slowing for the pedestrian ahead.", Factor.TRAFFIC_LIGHT, r)
    assert not g.ok and g.absent == (Factor.PEDESTRIAN,) and not g.names_factor


def test_the_hazard_that_forces_the_action_is_named() -> None:
    # a leader 6 m ahead closing at 5 m/s: slack (6 - 2 - 5^2/4) / 5 = -0.45 s; the
    # crossing 42 m ahead at 10 m/s: (42 - 25) / 10 = 1.7 s
    closing = rec("fast", -3, d_lead=6.0, dv=5.0, d_cross=42.0)
    assert rule_decision(closing).factor is Factor.LEAD_VEHICLE
    # a red light 15 m ahead (inside the 25 m stopping distance: -1.0 s) before a crossing
    # 30 m ahead (0.5 s)
    light_first = rec("fast", -2, d_tl=15.0, tl_state="red", d_cross=30.0)
    assert rule_decision(light_first).factor is Factor.TRAFFIC_LIGHT
    assert [h.factor for h in braking_hazards(light_first.nearby())] == [
        Factor.TRAFFIC_LIGHT,
        Factor.PEDESTRIAN,
    ]
    assert [round(h.slack_s, 2) for h in braking_hazards(light_first.nearby())] == [-1.0, 0.5]
    # the same crossing nearer than the light leads
    assert rule_decision(rec("fast", -2, d_tl=30.0, tl_state="red", d_cross=15.0)).factor is (
        Factor.PEDESTRIAN
    )


def test_braking_for_a_yield_line_is_giving_way() -> None:
    # 8 m/s, the line 20 m ahead: slack (20 - 8^2 / 4) / 8 = 0.5 s
    braking = rec("fast", -2, v_ego=8.0, d_yield=20.0)
    d = rule_decision(braking)
    assert d.explain and d.factor is Factor.GIVE_WAY and d.conflict is Conflict.SLOWS
    assert [(h.factor, h.slack_s) for h in braking_hazards(braking.nearby())] == [
        (Factor.GIVE_WAY, 0.5)
    ]
    # the line 15 m ahead (-1.0 s) before a red light at the next junction 40 m ahead (1.5 s)
    both = rec("fast", -2, d_yield=15.0, d_tl=40.0, tl_state="red")
    assert [(h.factor, h.slack_s) for h in braking_hazards(both.nearby())] == [
        (Factor.GIVE_WAY, -1.0),
        (Factor.TRAFFIC_LIGHT, 1.5),
    ]
    # a stopped car 6 m ahead at 4 m/s: (6 - 2 - 4^2 / 4) / 4 = 0 s, before the line: 2.5 s
    queue = rec("fast", -2, v_ego=4.0, d_lead=6.0, dv=4.0, d_yield=14.0)
    assert rule_decision(queue).factor is Factor.LEAD_VEHICLE


def test_what_needs_no_explanation_at_a_yield_line() -> None:
    assert not rule_decision(rec("comfort", -1, v_ego=8.0, d_yield=20.0)).explain
    assert not rule_decision(rec("stop", -2, v_ego=8.0, d_yield=20.0)).explain
    far = rule_decision(rec("fast", -1, d_yield=60.0))  # beyond the 50 m cut-off
    assert not far.explain and far.conflict is Conflict.SLOWS


def test_a_wait_at_a_yield_line_is_giving_way() -> None:
    waiting = StateRecord.model_validate(
        {
            "request": "comfort",
            "action": 0,
            "state": {"v_ego": 0.0, "v_lim": 13.9, "d_yield": 2.5},
            "history": {"slow_s": 8.0, "stopped_s": 6.0},
        }
    )
    d = rule_decision(waiting)
    assert d.explain and d.factor is Factor.GIVE_WAY and d.conflict is Conflict.WAITS
    # nearest first: the line 8 m ahead, then a red light 30 m ahead
    s = rec("fast", 0, d_yield=8.0, d_tl=30.0, tl_state="red").nearby()
    assert holding_factors(s) == [Factor.GIVE_WAY, Factor.TRAFFIC_LIGHT]


def test_a_waiting_car_ranks_what_is_nearest() -> None:
    # standing: slack is distance over 1 m/s
    waiting = rec("fast", 0, v_ego=0.0, d_tl=25.0, tl_state="red", d_cross=3.0)
    assert [h.slack_s for h in braking_hazards(waiting.nearby())] == [3.0, 25.0]
    assert rule_decision(waiting).factor is Factor.PEDESTRIAN


SWEEP_STATES: list[dict[str, Any]] = [
    {"d_tl": 30.0, "tl_state": "red"},
    {"d_tl": 40.0, "tl_state": "red", "d_cross": 25.0},
    {"d_tl": 12.0, "tl_state": "yellow", "d_lead": 8.0, "dv": 2.0},
    {"d_cross": 18.0, "d_lead": 6.0, "dv": 0.0},
    {"v_lim": 8.3},
]


@pytest.mark.parametrize("state", SWEEP_STATES)
@pytest.mark.parametrize("request_", ["fast", "comfort"])
def test_template_wording_is_true_of_the_action_and_speed(
    state: dict[str, Any], request_: str
) -> None:
    checked = 0
    for speed in (0.0, 0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 10.0, 13.0):
        for action in (-3, -2, -1, 0):
            r = rec(request_, action, v_ego=speed, **state)
            for factor in sorted(present_factors(r.nearby()) - {Factor.SPEED_LIMIT}) or [
                Factor.SPEED_LIMIT
            ]:
                text = TemplateExplainer().explain(r, factor).text
                assert wording_problems(text, r) == [], text
                assert reply_problems(text, r, factor) == [], text
                checked += 1
    assert checked >= 36


@pytest.mark.parametrize("speed", [8.0, 9.0, 10.0, 11.0, 12.0, 13.0])
@pytest.mark.parametrize("distance", [30.0, 35.0, 40.0])
def test_comfort_braking_before_a_red_light_is_not_called_a_stop(
    speed: float, distance: float
) -> None:
    firm = TemplateExplainer().explain(
        rec("comfort", -2, v_ego=speed, d_tl=distance, tl_state="red"), Factor.TRAFFIC_LIGHT
    )
    assert "stop" not in firm.text.lower() and "sorry" in firm.text.lower()
    hard = TemplateExplainer().explain(
        rec("comfort", -3, v_ego=speed, d_tl=distance, tl_state="red"), Factor.TRAFFIC_LIGHT
    )
    assert "easing off" not in hard.text
    assert any(word in hard.text for word in ("hard", "sharply"))


def test_stop_words_only_when_the_car_ends_the_step_at_rest() -> None:
    stopping = rec("fast", -3, v_ego=2.5, d_tl=4.0, tl_state="red")  # 2.5 - 3 <= 0.5
    text = TemplateExplainer().explain(stopping, Factor.TRAFFIC_LIGHT).text
    assert "stop" in text or "halt" in text
    moving = rec("fast", -3, v_ego=12.0, d_lead=5.0, dv=6.0)
    assert wording_problems("Sorry about that quick stop.", moving) == [
        "says a stop while the action is -3 m/s at 12.0 m/s"
    ]
    assert wording_problems("I'm easing off a little.", moving) == [
        "says gentle braking while the action is -3 m/s at 12.0 m/s"
    ]


@pytest.mark.parametrize("action", [2, 3])
def test_acceleration_through_a_yellow_light_is_explained_truly(action: int) -> None:
    r = rec("comfort", action, v_ego=12.0, d_tl=15.0, tl_state="yellow")
    text = TemplateExplainer().explain(r, Factor.TRAFFIC_LIGHT).text
    assert "15 m" in text and "yellow" in text
    assert reply_problems(text, r, Factor.TRAFFIC_LIGHT) == []
    with pytest.raises(ValueError, match="cannot be explained"):
        template_explanation(rec("comfort", 2, d_tl=15.0, tl_state="red"), Factor.TRAFFIC_LIGHT)


@pytest.mark.parametrize("action", [-1, -2, -3])
def test_a_standing_car_is_never_said_to_brake(action: int) -> None:
    r = rec("fast", action, v_ego=0.0, d_tl=5.0, tl_state="red")
    text = TemplateExplainer().explain(r, Factor.TRAFFIC_LIGHT).text
    assert text.startswith(("We're waiting here", "I'm keeping us stopped", "We're staying put")), (
        text
    )
    assert reply_problems(text, r, Factor.TRAFFIC_LIGHT) == []
    said = wording_problems("I'm reducing our speed a little for the red light.", r)
    assert f"says slowing down while the action is {action:+d} m/s at 0.0 m/s" in said


@pytest.mark.parametrize(
    ("v_ego", "action", "kind"),
    [(0.0, 0, "wait"), (0.3, -3, "wait"), (8.0, 0, "hold"), (8.0, -1, "gentle_brake"),
     (8.0, -3, "hard_brake"), (2.0, -3, "stopping"), (0.0, 2, "accelerate")],
)  # fmt: skip
def test_the_opener_follows_speed_and_action(v_ego: float, action: int, kind: str) -> None:
    from explaindrive.language.explanation.explainer import opener_kind

    assert opener_kind(rec("fast", action, v_ego=v_ego)) == kind


@pytest.mark.parametrize(
    ("v_ego", "d_lead", "dv", "action", "explained"),
    [
        (13.0, 40.0, 3.0, -3, True),  # closing: explained by the leader
        (13.0, 48.0, 1.0, -2, True),
        (13.0, 45.0, 0.0, -3, True),  # headway 45 / 13 = 3.5 s < 4 s
        (10.0, 45.0, -1.0, -3, False),  # pulling away, headway 4.5 s
        (13.0, 56.0, 3.0, -3, False),  # beyond the 50 m cut-off
        (13.0, 40.0, 3.0, -1, False),  # gentle braking needs no leader to explain it
    ],
)
def test_firm_braking_behind_a_leader_under_fast(
    v_ego: float, d_lead: float, dv: float, action: int, explained: bool
) -> None:
    r = rec("fast", action, v_ego=v_ego, v_lim=13.9, d_lead=d_lead, dv=dv)
    d = RuleDecider().decide(r)
    assert d.explain is explained
    if explained:
        assert d.factor is Factor.LEAD_VEHICLE
        text = TemplateExplainer().explain(r, d.factor).text
        assert f"{d_lead:.0f} m" in text and reply_problems(text, r, d.factor) == []


# --- what a passenger notices over several steps (the ride's history) ------------------------


def hrec(request: str, action: int, history: dict[str, float], **state: Any) -> StateRecord:
    base: dict[str, Any] = {"v_ego": 5.0, "v_lim": 13.9}
    base.update(state)
    return StateRecord.model_validate(
        {"request": request, "action": action, "state": base, "history": history}
    )


def test_a_lasting_delay_behind_a_slower_car_is_explained_under_fast() -> None:
    # 5 m/s behind a car at the same speed 30 m ahead: no hazard (headway 6 s), but the
    # car has been 8.9 m/s under the limit for 8 s
    d = rule_decision(hrec("fast", 0, {"slow_s": 8.0}, d_lead=30.0, dv=0.0))
    assert d.explain and d.factor is Factor.LEAD_VEHICLE and d.conflict is Conflict.SLOWS
    assert not rule_decision(hrec("fast", 0, {"slow_s": 4.0}, d_lead=30.0, dv=0.0)).explain
    # the same step without its history explains nothing, as before
    assert not rule_decision(rec("fast", 0, v_ego=5.0, d_lead=30.0, dv=0.0)).explain


def test_a_felt_drop_is_explained_and_a_recovering_car_is_not() -> None:
    # losing 3 m/s in 3 s behind a leader doing 9 - 1 = 8 m/s <= 13.9 - 3
    d = rule_decision(hrec("fast", -1, {"drop_mps": 3.0}, v_ego=9.0, d_lead=45.0, dv=1.0))
    assert d.explain and d.factor is Factor.LEAD_VEHICLE
    small = hrec("fast", -1, {"drop_mps": 2.9}, v_ego=9.0, d_lead=45.0, dv=1.0)
    assert not rule_decision(small).explain
    assert not rule_decision(hrec("fast", 1, {"slow_s": 9.0}, d_lead=30.0, dv=-1.0)).explain


def test_a_leader_near_the_limit_holds_no_one_back() -> None:
    # leader at 10 - (-1) = 11 m/s > 13.9 - 3 = 10.9: not slower than the road allows
    s = hrec("fast", 0, {"slow_s": 9.0}, v_ego=10.0, d_lead=40.0, dv=-1.0)
    assert holding_factors(s.nearby()) == []
    assert not rule_decision(s).explain


def test_a_lasting_standstill_under_comfort_names_the_nearest_cause() -> None:
    light = {"d_tl": 30.0, "tl_state": "red"}
    queue = hrec("comfort", 0, {"stopped_s": 9.0}, v_ego=0.0, d_lead=6.0, dv=0.0, **light)
    d = rule_decision(queue)
    assert d.explain and d.conflict is Conflict.WAITS and d.factor is Factor.LEAD_VEHICLE
    d = rule_decision(hrec("comfort", 0, {"stopped_s": 9.0}, v_ego=0.0, d_cross=6.0, **light))
    assert d.factor is Factor.PEDESTRIAN
    assert not rule_decision(hrec("comfort", 0, {"stopped_s": 4.0}, v_ego=0.0, **light)).explain
    assert not rule_decision(hrec("stop", 0, {"stopped_s": 20.0}, v_ego=0.0, **light)).explain
    assert not rule_decision(hrec("comfort", 0, {"stopped_s": 20.0}, v_ego=0.0)).explain


def test_the_delay_explanation_names_the_slower_car_and_what_the_car_does() -> None:
    r = hrec("fast", 0, {"slow_s": 8.0}, d_lead=30.0, dv=0.0)
    text = template_explanation(r, Factor.LEAD_VEHICLE)
    assert text == (
        "We're holding 18 km/h behind the slower car ahead, 30 m away, which is doing 18 km/h. "
        "I'll speed up when it clears."
    )
    assert check_grounding(text, Factor.LEAD_VEHICLE, r).ok
    queue = hrec("comfort", 0, {"stopped_s": 7.0}, v_ego=0.0, d_lead=4.0, dv=0.0)
    assert template_explanation(queue, Factor.LEAD_VEHICLE) == (
        "We're waiting behind the stopped car ahead, 4 m away. We'll move on as soon as it does."
    )


def test_a_cause_is_present_while_it_still_gives_a_reason() -> None:
    from explaindrive.language.explanation.explainer import cause_present

    s = rec("fast", 0, d_tl=20.0, tl_state="green", d_lead=15.0, dv=0.0).nearby()
    assert not cause_present(s, Factor.TRAFFIC_LIGHT)  # green is no reason
    assert cause_present(s, Factor.LEAD_VEHICLE) and cause_present(s, Factor.SPEED_LIMIT)
    assert not cause_present(s, Factor.PEDESTRIAN) and cause_present(s, None)
