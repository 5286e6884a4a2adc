"""The Python ride of docs/ride.md runs as written there."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "ride.md"


def python_ride_snippet() -> str:
    """The first ``python`` block under "A ride from Python" in docs/ride.md."""
    section = DOC.read_text(encoding="utf-8").split("## A ride from Python", 1)[1]
    match = re.search(r"```python\n(.*?)```", section, re.DOTALL)
    assert match is not None, "docs/ride.md lost its Python ride"
    return match.group(1)


def test_the_snippet_is_under_15_lines() -> None:
    assert len(python_ride_snippet().strip().splitlines()) < 15


@pytest.mark.slow
@pytest.mark.models
def test_the_python_ride_stops_the_car_on_request() -> None:
    scope: dict[str, object] = {}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(python_ride_snippet(), str(DOC), "exec"), scope)
    # the request at 20 s is confirmed once and STOP holds to the end of the 60 s ride
    assert out.getvalue().split() == ["stop", "1"]
    session = scope["session"]
    assert len(session.records) == 60  # type: ignore[attr-defined]
