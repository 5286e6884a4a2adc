"""Bad input to the CLI ends in one line on stderr and exit status 2, never a traceback.

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


def run(*args: str, cwd: Path, timeout_s: float = 120) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "explaindrive.cli.main", *args],
        cwd=cwd,
        env=ENV,
        capture_output=True,
        text=True,
        timeout=timeout_s,
    )


def one_error_line(res: subprocess.CompletedProcess[str]) -> str:
    """The one error line on stderr (stdout stays empty: errors never go there)."""
    lines = res.stderr.strip().splitlines()
    assert res.returncode == 2, res.stdout + res.stderr
    assert res.stdout == "", res.stdout
    assert len(lines) == 1 and lines[0].startswith("error: "), lines
    assert "Traceback" not in res.stdout + res.stderr
    return lines[0]


def make_inputs(root: Path) -> None:
    """The files the battery names: a file, a folder, text that is not UTF-8, a policy file
    that is not one, and 700 s of (silent, so tiny) FLAC audio."""
    import numpy as np
    import soundfile as sf

    (root / "afile").write_text("x")
    (root / "adir").mkdir()
    (root / "latin1.yaml").write_bytes(b"lr: 0.001 # d\xe9faut\n")
    (root / "corrupt.pt").write_bytes(b"PK\x03\x04 not a policy" * 20)
    sf.write(root / "long.flac", np.zeros(16_000 * 700, dtype=np.int16), 16_000)


# (arguments, the error line; "..." at its end: the line starts with the text before it)
BATTERY: list[tuple[list[str], str]] = [
    (["ride", "--out", "afile/ride"], "error: --out afile/ride: afile is a file, not a folder"),
    (
        ["ride", "--max-steps", "1000000000"],
        "error: invalid ride config: max_steps: Input should be less than or equal to 7200, "
        "got 1000000000",
    ),
    (["ride", "--seed", "-1"], "error: Invalid value for '--seed': ..."),
    (["ride", "--cooldown", "1e9"], "error: invalid ride config: explanation_cooldown_s: ..."),
    (
        ["ride", "--fast-policy", "corrupt.pt"],
        "error: corrupt.pt is not an explaindrive policy file (torch cannot read it: ...",
    ),
    (["demo", "--seed", "-1"], "error: Invalid value for '--seed': ..."),
    (
        ["evaluate", "fast", "--seeds", "0-99999999"],
        "error: seed list '0-99999999' names 100000000 or more seeds; at most 1000 in a run",
    ),
    (
        ["evaluate", "fast", "--max-steps", "1000000000"],
        "error: Invalid value for '--max-steps': Input should be less than or equal to 7200",
    ),
    (["evaluate", "fast", "--workers", "100000"], "error: Invalid value for '--workers': ..."),
    (
        ["evaluate", "fast", "--ray-address", "bogus:1"],
        "error: no Ray cluster answers at --ray-address bogus:1 (...",
    ),
    (["evaluate", "fast", "--json", "adir"], "error: --json adir is a folder; name a file"),
    (
        ["evaluate", "fast", "--figures", "afile"],
        "error: --figures afile is a file, not a folder; name a folder",
    ),
    (
        ["evaluate", "corrupt.pt", "--seeds", "0"],
        "error: corrupt.pt is not an explaindrive policy file (torch cannot read it: ...",
    ),
    (
        ["train", "--mode", "fast", "--out", "afile"],
        "error: --out afile is a file, not a folder; name a folder",
    ),
    (
        ["train", "--mode", "fast", "--config", "latin1.yaml"],
        "error: config file latin1.yaml is not UTF-8 text (byte 13: invalid continuation byte)",
    ),
    (
        ["train", "--mode", "fast", "--ray-address", "bogus:1"],
        "error: no Ray cluster answers at --ray-address bogus:1 (...",
    ),
    (
        ["train", "--mode", "fast", "--episodes", "0"],
        "error: Invalid value for '--episodes' / '-n': ...",
    ),
    (
        ["train", "--mode", "fast", "--set", "buffer_size=1000000000000"],
        "error: invalid training config: buffer_size: Input should be less than or equal to "
        "20000000, got 1000000000000",
    ),
    (["score", "intents", "--json", "adir"], "error: --json adir is a folder; name a file"),
    (["score", "decisions", "--json", "adir"], "error: --json adir is a folder; name a file"),
    (
        ["scenario", "build", "--out", "afile"],
        "error: --out afile is a file, not a folder; name a folder",
    ),
    (["scenario", "plot", "--out", "adir"], "error: --out adir is a folder; name a file"),
    (["report", "--out", "adir"], "error: --out adir is a folder; name a file"),
    (["report", "--external", "nope.json"], "error: evaluation file not found: nope.json"),
    (["report", "--runs", "nope"], "error: --runs nope: no such folder"),
    (
        ["report", "--runs", "adir", "--policies", "comfort,krauss"],
        "error: --runs adir: no training log adir/comfort/episodes.csv",
    ),
    (
        ["report", "--json", "afile/r.json"],
        "error: --json afile/r.json: afile is a file, not a folder",
    ),
    (
        ["transcribe", "long.flac"],
        "error: long.flac: the recording is longer than 600 s; say the request in a sentence "
        "or two",
    ),
    (
        ["interpret", "--config", "latin1.yaml", "go faster"],
        "error: latin1.yaml: not UTF-8 text (byte 13: invalid continuation byte)",
    ),
    (["serve", "--port", "0"], "error: Invalid value for '--port': ..."),
]


@pytest.mark.parametrize(("args", "expected"), BATTERY, ids=[" ".join(args) for args, _ in BATTERY])
def test_bad_input_is_one_line_and_exit_2_within_15_s(
    tmp_path: Path, args: list[str], expected: str
) -> None:
    make_inputs(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    line = one_error_line(run(*args, cwd=tmp_path, timeout_s=15 * 4))  # 15 s on a free CPU
    if expected.endswith("..."):
        assert line.startswith(expected[:-3]), line
    else:
        assert line == expected
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing made, nothing lost


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
