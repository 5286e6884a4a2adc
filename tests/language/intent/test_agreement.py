"""The policy between the remote and the embedded reading: one test per rule."""

from __future__ import annotations

from explaindrive.commands import Command
from explaindrive.language.intent.agreement import (
    SURE_P,
    TwoReadings,
    Verdict,
    reconcile,
    trust_sweep,
)

FAST, COMFORT, STOP = Command.FAST, Command.COMFORT, Command.STOP
SURE, UNSURE = SURE_P, SURE_P - 0.01


def test_stop_local_wins_whatever_the_remote_says() -> None:
    assert reconcile(STOP, 0.31, FAST) == Verdict(STOP, "embedded", "stop-local")
    assert reconcile(STOP, 0.31, None) == Verdict(STOP, "embedded", "stop-local")


def test_stop_remote_wins_over_an_unsure_reading_only() -> None:
    assert reconcile(FAST, UNSURE, STOP) == Verdict(STOP, "openai", "stop-remote")
    assert reconcile(None, UNSURE, STOP) == Verdict(STOP, "openai", "stop-remote")
    assert reconcile(FAST, 0.975, STOP) == Verdict(FAST, "embedded", "local-sure")
    assert reconcile(None, SURE, STOP) == Verdict(None, "embedded", "local-sure-none")


def test_agreement() -> None:
    assert reconcile(COMFORT, 0.4, COMFORT) == Verdict(COMFORT, "both", "agree")
    assert reconcile(None, 0.4, None) == Verdict(None, "both", "agree")


def test_a_sure_none_is_not_turned_into_a_driving_change() -> None:
    assert reconcile(None, SURE, FAST) == Verdict(None, "embedded", "local-sure-none")
    assert reconcile(None, SURE, COMFORT) == Verdict(None, "embedded", "local-sure-none")


def test_a_sure_command_stands() -> None:
    assert reconcile(FAST, SURE, COMFORT) == Verdict(FAST, "embedded", "local-sure")
    assert reconcile(COMFORT, SURE, None) == Verdict(COMFORT, "embedded", "local-sure")


def test_remote_none_against_an_unsure_command_asks_to_rephrase() -> None:
    assert reconcile(FAST, UNSURE, None) == Verdict(None, "openai", "remote-none")


def test_remote_command_against_an_unsure_reading() -> None:
    assert reconcile(FAST, UNSURE, COMFORT) == Verdict(COMFORT, "openai", "remote")
    assert reconcile(None, UNSURE, FAST) == Verdict(FAST, "openai", "remote")


def test_the_trust_threshold_is_the_models() -> None:
    # at 0 every embedded reading is sure: the model can only agree
    assert reconcile(FAST, 0.4, COMFORT, sure_p=0.0) == Verdict(FAST, "embedded", "local-sure")
    assert reconcile(None, 0.4, STOP, sure_p=0.0) == Verdict(None, "embedded", "local-sure-none")
    # at 1 the model changes any reading it does not share, but a STOP of the embedded one
    assert reconcile(FAST, 0.99, COMFORT, sure_p=1.0) == Verdict(COMFORT, "openai", "remote")
    assert reconcile(STOP, 0.4, FAST, sure_p=1.0) == Verdict(STOP, "embedded", "stop-local")


def test_the_trust_sweep_scores_each_threshold_on_the_same_replies() -> None:
    lines = [
        # the model is right where the embedded reader is unsure (0.6) ...
        TwoReadings("comfort", FAST, 0.6, COMFORT, True),
        # ... and wrong where it is sure (0.9)
        TwoReadings("fast", FAST, 0.9, STOP, True),
        # a sure off-topic line the model reads as fast
        TwoReadings("none", None, 0.85, FAST, True),
        # an unreadable reply: the embedded reading stands at every threshold
        TwoReadings("stop", STOP, 1.0, None, False),
    ]
    rows = {r["sure_p"]: r for r in trust_sweep(lines, (0.0, 0.7, 0.95))}
    # 0: only the embedded readings: comfort line wrong; fast, stop right; none right
    assert rows[0.0] == {"sure_p": 0.0, "accuracy": 0.6667, "none_rejection": 1.0,
                         "stop_recall": 1.0}  # fmt: skip
    # 0.7: the model fixes the comfort line, the sure readings stand
    assert rows[0.7]["accuracy"] == 1.0 and rows[0.7]["none_rejection"] == 1.0
    # 0.95: the model's STOP and fast replace sure readings too
    assert rows[0.95]["accuracy"] == 0.6667 and rows[0.95]["none_rejection"] == 0.0
    assert trust_sweep([TwoReadings("none", None, 0.9, None, True)])[0]["accuracy"] is None
