"""Ctrl+C during a real ``explaindrive ride`` leaves a consistent record of that ride."""

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
STEPS_BEFORE_CTRL_C = 4  # lines in events.jsonl when Ctrl+C is pressed


def test_ctrl_c_writes_the_summary_of_that_ride_marked_interrupted(tmp_path: Path) -> None:
    out = tmp_path / "ride"
    out.mkdir()  # a previous ride's files, replaced because of --force
    (out / "summary.json").write_text('{"previous ride": true}')
    (out / "events.jsonl").write_text('{"t": 1.0}\n' * 300)
    (out / "ride.png").write_bytes(b"old figure")
    events = out / "events.jsonl"
    cmd = [sys.executable, "-m", "explaindrive.cli.main", "ride", "--no-live", "--realtime"]
    proc = subprocess.Popen(
        [*cmd, "--seed", str(SEED), "--out", str(out), "--force"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        end = time.monotonic() + 300  # the language models load first
        while _lines(events) < STEPS_BEFORE_CTRL_C or (out / "summary.json").exists():
            assert proc.poll() is None, proc.communicate()[0]
            assert time.monotonic() < end, "the ride did not get going"
            time.sleep(0.2)
        proc.send_signal(signal.SIGINT)
        output, _ = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, output
    summary = json.loads((out / "summary.json").read_text())
    steps = [json.loads(line) for line in events.read_text().splitlines()]
    assert "previous ride" not in summary and summary["config"]["seed"] == SEED
    assert summary["interrupted"] is True
    assert summary["interruption"] == "stopped by the passenger (Ctrl+C)"
    assert summary["steps"] == len(steps) >= STEPS_BEFORE_CTRL_C
    assert [s["t"] for s in steps] == [float(t) for t in range(1, len(steps) + 1)]
    assert (out / "ride.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.iterdir()) == ["events.jsonl", "ride.png", "summary.json"]
    assert output.strip().splitlines()[-1].endswith("summary.json marks it interrupted")
    assert "Traceback" not in output


def _lines(path: Path) -> int:
    try:
        return len(path.read_text().splitlines())
    except FileNotFoundError:
        return 0
