"""Scenario options that cannot be used end in one line and exit status 2."""

from __future__ import annotations

from pathlib import Path

import pytest

from explaindrive.sim.scenario.files import default_scenario
from tests.cli.test_bad_inputs import one_error_line, run

pytestmark = pytest.mark.slow  # a subprocess per case


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["evaluate", "krauss", "--net", "missing.net.xml", "--route", "a,b"],
         "error: network file not found: missing.net.xml"),
        (["evaluate", "krauss", "--net", "PAPER", "--route", "J2_E0,W0_J1"],
         "error: no path for cars from edge 'J2_E0' to 'W0_J1' in"),
        (["ride", "--net", "PAPER", "--route", "W0_J1,nowhere", "--out", "r"],
         "error: edge 'nowhere' not found in"),
        (["evaluate", "krauss", "--scenario", "random"],
         "error: --scenario random draws scenarios while training"),
        (["evaluate", "krauss", "--scenarios", "random:1000000"],
         "error: scenario seed(s) [1000000] are not held out"),
        (["train", "--mode", "fast", "--scenario", "nowhere"],
         "error: scenario directory not found: nowhere"),
        (["scenario", "build", "--set", "limit_kmh=90", "--out", "s"],
         "error: invalid scenario: limit_kmh: Input should be less than or equal to 70"),
    ],
)  # fmt: skip
def test_unusable_scenarios_are_one_line(args: list[str], message: str, tmp_path: Path) -> None:
    paper = str(default_scenario().net_file)
    line = one_error_line(run(*(paper if a == "PAPER" else a for a in args), cwd=tmp_path))
    assert line.startswith(message), line
