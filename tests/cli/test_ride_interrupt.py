"""Signals during a real ``explaindrive ride`` leave a consistent record of that ride, or
the previous ride's record as it was; never a traceback."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

SEED = 5
STEPS_BEFORE_SIGNAL = 4  # lines in events.jsonl when the signal is sent
PREVIOUS = {"summary.json": '{"previous ride": true}', "events.jsonl": '{"t": 1.0}\n' * 300}


def start_ride(tmp_path: Path, *extra: str) -> tuple[subprocess.Popen[str], Path]:
    """A real-time ride with ``--force`` over a previous ride's files in ``tmp_path/ride``."""
    out = tmp_path / "ride"
    out.mkdir()
    for name, text in PREVIOUS.items():
        (out / name).write_text(text)
    (out / "ride.png").write_bytes(b"old figure")
    cmd = [sys.executable, "-m", "explaindrive.cli", "ride", "--no-live", "--realtime"]
    proc = subprocess.Popen(
        [*cmd, "--seed", str(SEED), "--out", str(out), "--force", *extra],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    return proc, out


def wait_for_steps(proc: subprocess.Popen[str], out: Path, steps: int) -> None:
    events = out.parent / f".{out.name}.new" / "events.jsonl"  # the ride's staging folder
    end = time.monotonic() + 300  # the language models load first
    while _lines(events) < steps:
        assert proc.poll() is None, proc.communicate()[0]
        assert time.monotonic() < end, "the ride did not get going"
        time.sleep(0.2)


def finish(proc: subprocess.Popen[str]) -> str:
    try:
        output, _ = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert "Traceback" not in output, output
    return output


def assert_consistent_record(out: Path, signal_name: str, reason: str) -> dict:
    summary = json.loads((out / "summary.json").read_text())
    steps = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    assert "previous ride" not in summary and summary["config"]["seed"] == SEED
    assert summary["interrupted"] is True
    assert (summary["interruption"], summary["signal"]) == (reason, signal_name)
    assert summary["steps"] == len(steps) >= STEPS_BEFORE_SIGNAL
    assert [s["t"] for s in steps] == [float(t) for t in range(1, len(steps) + 1)]
    assert (out / "ride.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.iterdir()) == ["events.jsonl", "ride.png", "summary.json"]
    assert sorted(p.name for p in out.parent.iterdir() if p.name.startswith(".")) == []
    return summary


def assert_previous_ride_untouched(out: Path) -> None:
    for name, text in PREVIOUS.items():
        assert (out / name).read_text() == text
    assert (out / "ride.png").read_bytes() == b"old figure"
    assert not (out.parent / f".{out.name}.new").exists()


@pytest.mark.parametrize(
    ("signals", "status", "name", "reason"),
    [
        ([signal.SIGINT], 130, "SIGINT", "stopped by SIGINT (Ctrl+C)"),
        ([signal.SIGINT, signal.SIGINT], 130, "SIGINT", "stopped by SIGINT (Ctrl+C)"),
        ([signal.SIGTERM], 143, "SIGTERM", "stopped by SIGTERM"),
    ],
    ids=["ctrl-c", "ctrl-c-twice-within-50ms", "sigterm"],
)
def test_a_signal_while_driving_writes_the_summary_of_that_ride(
    tmp_path: Path, signals: list[int], status: int, name: str, reason: str
) -> None:
    proc, out = start_ride(tmp_path)
    try:
        wait_for_steps(proc, out, STEPS_BEFORE_SIGNAL)
        for sig in signals:
            proc.send_signal(sig)
            time.sleep(0.05)
    finally:
        output = finish(proc)
    assert proc.returncode == status, output
    assert_consistent_record(out, name, reason)
    assert output.strip().splitlines()[-1].endswith("summary.json marks it interrupted")


def seconds_to_first_step(tmp_path: Path) -> float:
    """How long a ride takes from launch to making its staging folder, which it does just
    before its first step (a probe ride, interrupted there)."""
    probe = tmp_path / "probe"
    probe.mkdir()
    proc, out = start_ride(probe)
    staging, start = out.parent / f".{out.name}.new", time.monotonic()
    try:
        while not staging.exists():
            assert proc.poll() is None, proc.communicate()[0]
            assert time.monotonic() - start < 300, "the ride did not get going"
            time.sleep(0.01)
        return time.monotonic() - start
    finally:
        proc.send_signal(signal.SIGINT)
        finish(proc)


@pytest.mark.parametrize("phase", ["during-imports", "during-start-up"])
def test_a_signal_before_the_first_step_leaves_the_previous_ride_untouched(
    tmp_path: Path, phase: str
) -> None:
    # start-up: half way to the first step, however fast the machine loads the models
    delay_s = 0.3 if phase == "during-imports" else 0.5 * seconds_to_first_step(tmp_path)
    proc, out = start_ride(tmp_path)
    time.sleep(delay_s)
    proc.send_signal(signal.SIGINT)
    output = finish(proc)
    assert proc.returncode == 130, output
    assert_previous_ride_untouched(out)
    lines = output.strip().splitlines()
    assert len(lines) == 1, output
    assert lines[0] in (
        "error: stopped by SIGINT (Ctrl+C)",  # still importing the command modules
        f"stopped by SIGINT (Ctrl+C) before the ride started; {out} is unchanged",
    )


def _lines(path: Path) -> int:
    try:
        return len(path.read_text().splitlines())
    except FileNotFoundError:
        return 0
