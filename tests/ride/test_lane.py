"""The language lane: results, errors and deadlines."""

import time

from explaindrive.ride.lane import LanguageLane


def test_results_errors_and_late_tasks():
    lane = LanguageLane()
    try:
        lane.submit("interpret", lambda x: x * 2, 21, deadline_s=1.0, context={"id": 1})
        lane.submit("decide", lambda: 1 / 0, deadline_s=1.0)
        lane.submit("explain", time.sleep, 0.3, deadline_s=0.05)
        outcomes = lane.collect(wait=True)
        assert [o.task.kind for o in outcomes] == ["interpret", "decide", "explain"]
        ok, failed, late = outcomes
        assert ok.result == 42 and ok.error is None and ok.task.context == {"id": 1}
        assert failed.error == "ZeroDivisionError: division by zero"
        assert late.late and late.latency_s >= 0.05
        assert lane.pending == 0
    finally:
        lane.close()


def test_collect_without_wait_keeps_running_tasks():
    lane = LanguageLane()
    try:
        lane.submit("interpret", time.sleep, 0.2, deadline_s=2.0)
        assert lane.collect() == []
        assert lane.pending == 1
        (done,) = lane.collect(wait=True)
        assert not done.late and 0.2 <= done.latency_s < 2.0
    finally:
        lane.close()
