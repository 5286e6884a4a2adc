"""The ride's output folder holds one ride at every moment, finished or interrupted."""

from __future__ import annotations

import json
import signal
import threading
from pathlib import Path

import pytest

from explaindrive.ride.config import RideConfig
from explaindrive.ride.runner import (
    STOPPED,
    WRITE_LAG_STEPS,
    OutputDirError,
    StopRequest,
    commit_ride,
    discard_ride,
    prepare_out_dir,
    run_ride,
    staging_dir,
)
from explaindrive.ride.script import ScriptLine
from explaindrive.ride.session import RideSession, StepRecord

from .fakes import ScriptedController, fake_language


def make_session(max_steps: int = 40) -> RideSession:
    config = RideConfig(traffic_level=0.5, seed=3, max_steps=max_steps)
    return RideSession(config, ScriptedController(), fake_language())


def event_lines(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]


def summary(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def test_a_finished_ride_is_not_marked_interrupted(tmp_path: Path) -> None:
    session = make_session(max_steps=25)
    outputs = run_ride(session, [ScriptLine(t=30, say="hurry")], tmp_path)
    assert outputs.interrupted is None
    done = summary(tmp_path)
    assert (done["steps"], done["interrupted"], done["interruption"]) == (25, False, None)
    assert done["signal"] is None
    assert [e["t"] for e in event_lines(tmp_path)] == [float(t) for t in range(1, 26)]
    assert done["unused_script_lines"] == [
        {"t": 30.0, "say": "hurry", "audio": None, "confirm": None}
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "events.jsonl",
        "ride.png",
        "summary.json",
    ]


def test_events_are_written_while_the_ride_goes_on(tmp_path: Path) -> None:
    seen: list[tuple[float, int]] = []

    def count(rec: StepRecord) -> None:
        seen.append((rec.t, len((tmp_path / "events.jsonl").read_text().splitlines())))

    run_ride(make_session(max_steps=12), [], tmp_path, on_step=count)
    # after step t, the lines up to t - WRITE_LAG_STEPS are on disk (callback runs first)
    assert seen[:5] == [(1.0, 0), (2.0, 0), (3.0, 0), (4.0, 0), (5.0, 1)]
    assert seen[-1] == (12.0, 12 - WRITE_LAG_STEPS - 1)
    assert len(event_lines(tmp_path)) == 12  # the last ones when the ride ends


def test_a_stopped_ride_writes_every_step_and_says_so(tmp_path: Path) -> None:
    stop = threading.Event()

    def stop_at_10(rec: StepRecord) -> None:
        if rec.t >= 10:
            stop.set()

    session = make_session()
    outputs = run_ride(session, [], tmp_path, on_step=stop_at_10, stop=stop)
    assert outputs.interrupted == STOPPED
    result = summary(tmp_path)
    assert (result["steps"], result["interrupted"], result["interruption"]) == (10, True, STOPPED)
    assert len(event_lines(tmp_path)) == 10 == len(session.records)  # the held-back steps too
    assert (tmp_path / "ride.png").stat().st_size > 10_000
    assert not list(tmp_path.glob(".*"))  # no temporary files left


def test_ctrl_c_inside_the_loop_ends_the_ride_the_same_way(tmp_path: Path) -> None:
    def interrupt(rec: StepRecord) -> None:
        if rec.t >= 7:
            raise KeyboardInterrupt

    outputs = run_ride(make_session(), [], tmp_path, on_step=interrupt)
    assert outputs.interrupted == STOPPED
    assert summary(tmp_path)["steps"] == 7 == len(event_lines(tmp_path))


def test_a_ride_that_fails_writes_its_steps_then_raises(tmp_path: Path) -> None:
    session = make_session()
    step = session.step

    def failing_step() -> StepRecord:
        if len(session.records) == 6:
            raise RuntimeError("SUMO went away")
        return step()

    session.step = failing_step  # type: ignore[method-assign]
    with pytest.raises(RuntimeError, match="SUMO went away"):
        run_ride(session, [], tmp_path)
    result = summary(tmp_path)
    assert result["interrupted"] is True and result["steps"] == 6 == len(event_lines(tmp_path))
    assert result["interruption"] == "stopped on an error: RuntimeError: SUMO went away"


def test_prepare_out_dir_checks_the_folder_and_touches_nothing_in_it(tmp_path: Path) -> None:
    new = tmp_path / "a" / "b"
    assert prepare_out_dir(new) == tmp_path / "a" / ".b.new"
    assert list(tmp_path.iterdir()) == []  # nothing is made before the ride
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputDirError, match="is a file, not a folder"):
        prepare_out_dir(tmp_path / "file")
    with pytest.raises(OutputDirError, match=r"file/ride: .*file is a file, not a folder"):
        prepare_out_dir(tmp_path / "file" / "ride")
    new.mkdir(parents=True)
    for name in ("events.jsonl", "summary.json", "ride.png", "notes.txt"):
        (new / name).write_text("old ride")
    with pytest.raises(
        OutputDirError, match=r"not empty \(events.jsonl, notes.txt, ride.png, \.\.\.\).*--force"
    ):
        prepare_out_dir(new)
    staging_dir(new).mkdir()
    (staging_dir(new) / "events.jsonl").write_text("a ride killed outright")
    staging = prepare_out_dir(new, force=True)
    assert not staging.exists()  # removed; run_ride makes it afresh
    assert sorted(p.read_text() for p in new.iterdir()) == ["old ride"] * 4  # all kept


def test_a_committed_ride_replaces_the_previous_one_and_keeps_other_files(tmp_path: Path) -> None:
    out = tmp_path / "ride"
    out.mkdir()
    for name in ("events.jsonl", "summary.json", "ride.png", "notes.txt"):
        (out / name).write_text("old ride")
    staging = prepare_out_dir(out, force=True)
    run_ride(make_session(max_steps=5), [], staging)
    final = commit_ride(staging, out)
    assert final.summary == out / "summary.json" and summary(out)["steps"] == 5
    assert len(event_lines(out)) == 5 and (out / "notes.txt").read_text() == "old ride"
    assert not staging.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ride"]


def test_a_discarded_ride_leaves_the_previous_one_as_it_was(tmp_path: Path) -> None:
    out = tmp_path / "ride"
    out.mkdir()
    (out / "summary.json").write_text("old ride")
    staging = prepare_out_dir(out, force=True)
    staging.mkdir()
    (staging / "events.jsonl").write_text("")
    discard_ride(staging)
    assert [p.name for p in tmp_path.iterdir()] == ["ride"]
    assert (out / "summary.json").read_text() == "old ride"


def test_a_stop_request_names_its_signal_in_the_summary(tmp_path: Path) -> None:
    stop = StopRequest()

    def terminate_at_4(rec: StepRecord) -> None:
        if rec.t >= 4:
            stop.request(signal.SIGTERM)
            stop.request(signal.SIGINT)  # a later signal changes nothing

    outputs = run_ride(make_session(), [], tmp_path, on_step=terminate_at_4, stop=stop)
    assert outputs.interrupted == "stopped by SIGTERM"
    result = summary(tmp_path)
    assert (result["steps"], result["interruption"], result["signal"]) == (
        4,
        "stopped by SIGTERM",
        "SIGTERM",
    )
    assert STOPPED == "stopped by SIGINT (Ctrl+C)"
