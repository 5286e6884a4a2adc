"""Bad input to the CLI ends in one line and exit status 2, never a traceback.

Each case runs the real ``explaindrive`` command in a subprocess with a 50-column
terminal, so a long message that wrapped would show as two lines.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # a subprocess per case

ENV = {**os.environ, "COLUMNS": "50", "TERM": "dumb", "NO_COLOR": "1"}


def run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "explaindrive.cli.main", *args],
        cwd=cwd,
        env=ENV,
        capture_output=True,
        text=True,
        timeout=120,
    )


def one_error_line(res: subprocess.CompletedProcess[str]) -> str:
    lines = (res.stdout + res.stderr).strip().splitlines()
    assert res.returncode == 2, res.stdout + res.stderr
    assert len(lines) == 1 and lines[0].startswith("error: "), lines
    return lines[0]


def test_ride_out_naming_a_file(tmp_path: Path) -> None:
    (tmp_path / "taken").write_text("x")
    line = one_error_line(run("ride", "--no-live", "--out", "taken", cwd=tmp_path))
    assert line == "error: --out taken is a file, not a folder; name a folder"


def test_ride_out_holding_a_previous_ride(tmp_path: Path) -> None:
    (tmp_path / "r1").mkdir()
    (tmp_path / "r1" / "summary.json").write_text("{}")
    line = one_error_line(run("ride", "--no-live", "--out", "r1", cwd=tmp_path))
    assert line == (
        "error: --out r1 is not empty (summary.json); choose a new folder, or add --force "
        "to replace the ride in it"
    )
    assert (tmp_path / "r1" / "summary.json").read_text() == "{}"


def test_ride_with_a_missing_policy(tmp_path: Path) -> None:
    line = one_error_line(run("ride", "--no-live", "--fast-policy", "runs/x", cwd=tmp_path))
    assert line == "error: policy file not found: runs/x.pt"


def test_ride_script_with_a_missing_audio_file(tmp_path: Path) -> None:
    (tmp_path / "s.yaml").write_text("- {t: 0, say: hurry}\n- {t: 20, audio: stop.wav}\n")
    line = one_error_line(run("ride", "--no-live", "--script", "s.yaml", cwd=tmp_path))
    assert line == "error: ride script s.yaml, line 2: audio file not found: stop.wav"
    assert not (tmp_path / "out").exists()  # refused before --out was made


def test_ride_script_that_is_not_utf8(tmp_path: Path) -> None:
    (tmp_path / "s.yaml").write_bytes(b'- {t: 0, say: "vite s\'il vous pla\xeet"}\n')
    line = one_error_line(run("ride", "--no-live", "--script", "s.yaml", cwd=tmp_path))
    assert (
        line == "error: ride script s.yaml is not UTF-8 text (byte 33: invalid continuation byte)"
    )


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--cooldown", "nan"], "explanation_cooldown_s: Input should be a finite number, got nan"),
        (
            ["--cooldown", "-1"],
            "explanation_cooldown_s: Input should be greater than or equal to 0, got -1.0",
        ),
        (["--traffic", "nan"], "traffic_level: traffic level must be a finite number > 0, got nan"),
        (["--traffic", "99"], "traffic_level: traffic level must be at most 2, got 99"),
    ],
)
def test_ride_settings(tmp_path: Path, option: list[str], message: str) -> None:
    line = one_error_line(run("ride", "--no-live", *option, cwd=tmp_path))
    assert line.startswith(f"error: invalid ride config: {message}")


def test_train_refuses_a_traffic_level_the_scenario_cannot_carry(tmp_path: Path) -> None:
    args = ("train", "--mode", "fast", "--set", "traffic_levels=[99]", "--no-progress")
    line = one_error_line(run(*args, "--out", "run", cwd=tmp_path))
    assert line == (
        "error: invalid training config: traffic_levels.0: traffic level must be at most 2, "
        "got 99: on a busier road the ego cannot enter"
    )
    assert not (tmp_path / "run").exists()  # refused when read: no workers, no run folder


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b'"dv": NaN', "NaN is not allowed; give a finite number, or null"),
        (b'"dv": 1e999', "1e999 is not a finite number"),
        (b'"dv": -Infinity', "-Infinity is not allowed; give a finite number, or null"),
    ],
)
def test_explain_case_with_a_number_that_is_not_finite(
    tmp_path: Path, content: bytes, message: str
) -> None:
    case = b'{"request": "fast", "action": -2, "state": {"v_ego": 8, "v_lim": 13.9, '
    (tmp_path / "case.json").write_bytes(case + b'"d_lead": 20, ' + content + b"}}")
    line = one_error_line(run("explain", "--case", "case.json", cwd=tmp_path))
    assert line == f"error: case.json: {message}"


def test_explain_case_that_is_not_utf8(tmp_path: Path) -> None:
    (tmp_path / "case.json").write_bytes(b'{"request": "f\xe4st"}')
    line = one_error_line(run("explain", "--case", "case.json", cwd=tmp_path))
    assert line == "error: case.json: not UTF-8 text (byte 14: invalid continuation byte)"
