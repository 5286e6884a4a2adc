"""Explanations that arrive after their step: shown while their cause lasts (no SUMO)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from explaindrive.language.explanation.decision import Factor
from explaindrive.language.explanation.explainer import Explanation
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.ride.config import RideConfig
from explaindrive.ride.explaining import Explanations
from explaindrive.ride.jobs import ExplainJob
from explaindrive.ride.records import ModuleCounts, RideCounts, StepRecord


def step(t: float) -> StepRecord:
    return StepRecord(t, {}, "fast", "fast", 0, 5.0, 13.9, 0.0, {})


def record(**state: Any) -> StateRecord:
    return StateRecord.model_validate(
        {"request": "fast", "action": 0, "state": {"v_ego": 5.0, "v_lim": 13.9, **state}}
    )


def explanations(now: StateRecord, steps: int) -> Explanations:
    language: Any = SimpleNamespace(cutoff_m=50.0)
    records = [step(float(t + 1)) for t in range(steps)]
    ex = Explanations(
        RideConfig(), lane=None, language=language, counts=RideCounts(), records=records
    )  # type: ignore[arg-type]
    ex._now = (steps - 1, now)
    return ex


LEAD = Explanation("Behind the slower car ahead.", Factor.LEAD_VEHICLE, "openai", latency_s=2.5)


def test_a_late_explanation_is_shown_while_its_cause_lasts() -> None:
    ex = explanations(record(d_lead=30.0, dv=0.0), steps=4)
    ex.on_explanation(ExplainJob(1), LEAD, 2.5)
    shown = ex.records[1].explanation
    assert shown is not None and shown["shown_t"] == 4.0 and "shown" not in shown
    assert ex.counts.explanations == 1 and ex.latest is not None and ex.latest["t"] == 2.0
    assert ex.counts.models["explain"] == ModuleCounts(used=1)


def test_a_late_explanation_whose_cause_has_gone_is_not_shown() -> None:
    ex = explanations(record(), steps=4)  # the car ahead has gone
    ex.on_explanation(ExplainJob(1), LEAD, 2.5)
    assert ex.records[1].explanation is not None and ex.records[1].explanation["shown"] is False
    assert ex.counts.explanations == 0 and ex.latest is None
    assert ex.counts.models["explain"] == ModuleCounts(used=1, stale=1)


def test_an_answer_to_a_question_is_always_shown() -> None:
    ex = explanations(record(), steps=4)
    ex.on_explanation(ExplainJob(1, question=7), LEAD, 2.5)
    assert ex.counts.explanations == 1 and ex.latest is not None and ex.latest["question"] == 7


def test_a_red_light_that_turned_green_is_no_cause_any_more() -> None:
    light = Explanation("The light is red.", Factor.TRAFFIC_LIGHT, "embedded")
    ex = explanations(record(d_tl=20.0, tl_state="green"), steps=3)
    ex.on_explanation(ExplainJob(0), light, 1.5)
    assert ex.counts.models["explain"].stale == 1


def test_giving_way_is_no_cause_once_the_foe_has_passed() -> None:
    give_way = Explanation("We're giving way at the junction.", Factor.GIVE_WAY, "embedded")
    held = explanations(record(d_yield=3.0), steps=3)
    held.on_explanation(ExplainJob(0), give_way, 1.5)
    assert held.counts.models["explain"].stale == 0 and held.counts.explanations == 1
    passed = explanations(record(), steps=3)
    passed.on_explanation(ExplainJob(0), give_way, 1.5)
    assert passed.counts.models["explain"].stale == 1 and passed.counts.explanations == 0


def test_module_counts_put_a_veto_before_a_fallback() -> None:
    c = ModuleCounts()
    c.add(fallback=False, vetoed=False)
    c.add(fallback=True, vetoed=False)
    c.add(fallback=True, vetoed=True)  # a rejected reply: the template stood in
    assert c == ModuleCounts(used=1, fallback=1, vetoed=1)


def test_the_state_record_holds_the_yield_line_seen_with_the_observation() -> None:
    ex = explanations(record(), steps=1)
    # fast, 6 m/s on a 13.9 m/s road, the virtual leader at the yield line 12.5 m ahead
    seen = np.array([0, 6.0, 13.9, 12.5, 6.0, 200.0, 0, 200.0], dtype=np.float32)
    held = ex.state_record(seen, -2, yield_gap_m=12.5)
    assert (held.state.d_lead, held.state.d_yield, held.action) == (None, 12.5, -2)
    assert held.history is not None and held.history.slow_s == 1.0  # 6 <= 13.9 - 3
    free = ex.state_record(seen, -2, yield_gap_m=200.0)  # no line in force: a standing car
    assert (free.state.d_lead, free.state.d_yield) == (12.5, None)
