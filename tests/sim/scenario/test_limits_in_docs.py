"""The docs state the traffic range the code accepts (``MAX_TRAFFIC_LEVEL``), nothing else."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from explaindrive.sim.scenario.limits import MAX_TRAFFIC_LEVEL

DOCS = Path(__file__).resolve().parents[3] / "docs"
TRAFFIC_RANGE = re.compile(r"traffic[^\n]{0,40}?\(0, ([0-9.]+)\]", re.IGNORECASE)


@pytest.mark.parametrize("page", ["ride.md", "web.md", "evaluation.md"])
def test_every_traffic_range_in_the_docs_is_the_codes(page: str) -> None:
    bounds = TRAFFIC_RANGE.findall((DOCS / page).read_text(encoding="utf-8"))
    assert bounds, f"docs/{page} states no traffic range"
    assert {float(b) for b in bounds} == {MAX_TRAFFIC_LEVEL}


def test_the_pattern_finds_a_stale_bound() -> None:
    text = "`--traffic` (in (0, 1.5]), and traffic_level: (0, 2]"
    assert TRAFFIC_RANGE.findall(text) == ["1.5", "2"]
