"""The policy between the remote and the embedded reading: one test per rule."""

from __future__ import annotations

from explaindrive.commands import Command
from explaindrive.language.agreement import SURE_P, Verdict, reconcile

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
