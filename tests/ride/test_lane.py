"""The language lane: results, errors and deadlines."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest

from explaindrive.ride.inputs import TypedLine
from explaindrive.ride.jobs import Interpretation, InterpretJob
from explaindrive.ride.lane import LanguageLane
from explaindrive.ride.records import PassengerRequest


@pytest.fixture
def lane() -> Iterator[LanguageLane]:
    """A language lane, closed after the test."""
    lane = LanguageLane()
    yield lane
    lane.close()


def test_results_errors_and_late_tasks(lane: LanguageLane) -> None:
    job = InterpretJob(PassengerRequest(1, 0.0, TypedLine("  "), None))
    empty = Interpretation("  ", None, 0.0, "empty request")
    lane.submit("interpret", lambda x: x, empty, deadline_s=1.0, context=job)
    lane.submit("decide", lambda: 1 / 0, deadline_s=1.0)
    lane.submit("explain", time.sleep, 0.3, deadline_s=0.05)
    outcomes = lane.collect(wait=True)
    assert [o.task.kind for o in outcomes] == ["interpret", "decide", "explain"]
    ok, failed, late = outcomes
    assert ok.result is empty and ok.error is None and ok.task.context is job
    assert failed.error == "ZeroDivisionError: division by zero"
    assert late.late and late.latency_s >= 0.05
    assert lane.pending == 0


def test_collect_without_wait_keeps_running_tasks(lane: LanguageLane) -> None:
    lane.submit("interpret", time.sleep, 0.2, deadline_s=2.0)
    assert lane.collect() == []
    assert lane.pending == 1
    (done,) = lane.collect(wait=True)
    assert not done.late and 0.2 <= done.latency_s < 2.0


def test_explanations_never_delay_interpretation(lane: LanguageLane) -> None:
    lane.submit("decide", time.sleep, 1.0, deadline_s=2.0)
    lane.submit("explain", time.sleep, 1.0, deadline_s=2.0)
    lane.submit("interpret", lambda: "stop", deadline_s=2.0)
    time.sleep(0.2)
    (read,) = lane.collect()
    assert read.task.kind == "interpret" and read.result == "stop"
    assert read.latency_s < 0.2  # not behind the 2 s of explanation work
    assert lane.busy("explanation") and not lane.busy("interpretation")


def test_lines_are_interpreted_side_by_side(lane: LanguageLane) -> None:
    t0 = time.monotonic()
    for _ in range(3):
        lane.submit("interpret", time.sleep, 0.5, deadline_s=2.0)
    outcomes = lane.collect(wait=True)
    assert len(outcomes) == 3 and not any(o.late for o in outcomes)
    assert time.monotonic() - t0 < 1.0  # 3 x 0.5 s one after the other would be 1.5 s


def test_a_late_task_still_running_keeps_its_channel_busy(lane: LanguageLane) -> None:
    lane.submit("decide", time.sleep, 0.5, deadline_s=0.1)
    time.sleep(0.2)
    (late,) = lane.collect()
    assert late.late and lane.pending == 0
    assert lane.busy("explanation")  # its worker is still sleeping
    time.sleep(0.4)
    assert not lane.busy("explanation")


def test_unknown_task_kind_is_refused(lane: LanguageLane) -> None:
    with pytest.raises(ValueError, match="unknown language task 'summarise'"):
        lane.submit("summarise", print, deadline_s=1.0)


def test_working_counts_running_tasks_not_finished_ones(lane: LanguageLane) -> None:
    lane.submit("interpret", time.sleep, 0.3, deadline_s=2.0)
    lane.submit("decide", lambda: None, deadline_s=2.0)
    time.sleep(0.1)  # the decision is done, waiting to be collected; the line is not
    assert lane.working() == {"interpret"} and lane.pending == 2
    lane.collect(wait=True)
    assert lane.working() == set()
