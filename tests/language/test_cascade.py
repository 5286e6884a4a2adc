"""The LLM-1 cascade: confidence gap, escalation-margin tuning, the rule file, routing."""

from __future__ import annotations

import copy
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from explaindrive.commands import Command
from explaindrive.language.cascade import (
    CascadeRule,
    cascade_rows,
    confidence_gap,
    tune_escalation_margin,
)


def test_confidence_gap() -> None:
    p = np.array([[0.5, 0.3, 0.1, 0.1], [0.25, 0.25, 0.25, 0.25], [0.1, 0.1, 0.05, 0.75]])
    np.testing.assert_allclose(confidence_gap(p), [0.2, 0.0, 0.65])


# Five requests (labels: 0 fast, 1 comfort, 2 stop, 3 none). The small model is wrong on
# request 0 only (gap 0.05); the large model is right on it but wrong on request 1 (gap
# 0.12). Cost of a margin m: m < 0.05 -> 1 error; 0.05 <= m < 0.12 -> 0 (request 0 fixed);
# 0.12 <= m < 0.30 -> 1 (request 1 broken), 2 of 5 escalated; m >= 0.30 escalates 3 of 5.
GAP = np.array([0.05, 0.12, 0.30, 0.50, 0.70])
Y = np.array([1, 1, 2, 3, 0])
SMALL = np.array([0, 1, 2, 3, 0])
LARGE = np.array([1, 0, 2, 3, 0])


def test_cascade_rows() -> None:
    np.testing.assert_array_equal(cascade_rows(GAP, SMALL, LARGE, 0.05), [1, 1, 2, 3, 0])
    np.testing.assert_array_equal(cascade_rows(GAP, SMALL, LARGE, 0.2), [1, 0, 2, 3, 0])


def test_margin_is_the_cheapest_within_the_budget() -> None:
    assert tune_escalation_margin(GAP, SMALL, LARGE, Y, budget=0.4) == pytest.approx(0.05)
    # a budget of one request in ten allows no escalation here: the margin stays below 0.05
    assert tune_escalation_margin(GAP, SMALL, LARGE, Y, budget=0.1) == pytest.approx(0.0)


def test_rule_escalates_at_or_below_its_margin() -> None:
    rule = CascadeRule(0.2)
    assert rule.escalate(np.array([0.5, 0.3, 0.1, 0.1]))  # gap 0.2
    assert not rule.escalate(np.array([0.6, 0.3, 0.05, 0.05]))  # gap 0.3


def test_rule_file_round_trip_and_bad_files(tmp_path: Path) -> None:
    path = tmp_path / "rule.json"
    CascadeRule(0.13, 0.04, {"escalated": 0.03}).save(path)
    assert CascadeRule.load(path) == CascadeRule(0.13, 0.04, {"escalated": 0.03})
    with pytest.raises(FileNotFoundError, match="cascade rule not found"):
        CascadeRule.load(tmp_path / "missing.json")
    path.write_text("{oops")
    with pytest.raises(ValueError, match="not a cascade rule"):
        CascadeRule.load(path)
    path.write_text('{"escalation_margin": 1.5}')
    with pytest.raises(ValueError, match=r"must be a number in \[0, 1\]"):
        CascadeRule.load(path)


def test_shipped_rule_was_tuned_within_its_budget() -> None:
    rule = CascadeRule.load()
    assert rule.held_out is not None and 0.0 <= rule.escalation_margin <= 1.0
    assert rule.held_out["escalated"] <= rule.budget
    cascade, small = rule.held_out["cascade"], rule.held_out["minilm"]
    assert cascade["cost"] <= small["cost"] and cascade["stop_recall"] >= small["stop_recall"]


def test_interpreter_routes_unsure_requests_to_mpnet(interpreter) -> None:  # type: ignore[no-untyped-def]
    assert interpreter.rule is not None  # the default intent model is the cascade
    sure = interpreter.interpret("Stop the car right now, please!")
    assert sure.intent is Command.STOP and sure.model == "minilm"
    always = copy.copy(interpreter)  # shares the loaded models
    always.rule = replace(interpreter.rule, escalation_margin=1.0)
    r = always.interpret("Stop the car right now, please!")
    assert r.intent is Command.STOP and r.model == "mpnet"
    assert r.scores != sure.scores
