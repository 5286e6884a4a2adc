"""The page and the ride agree on the passenger event types (``ride/events.py``)."""

from __future__ import annotations

import re
from pathlib import Path

import explaindrive.web
from explaindrive.ride.events import EventType

APP_JS = Path(explaindrive.web.__file__).parent / "static" / "app.js"


def _describe_event_body(source: str) -> str:
    """The body of ``describeEvent``, the function that gives each event its line of text."""
    match = re.search(r"^function describeEvent\(e\) \{\n(.*?)^\}$", source, re.M | re.S)
    assert match, f"describeEvent not found in {APP_JS}"
    return match.group(1)


def test_the_page_has_a_line_for_every_event_type_and_no_other() -> None:
    rendered = re.findall(r'case "(\w+)":', _describe_event_body(APP_JS.read_text("utf-8")))
    assert len(rendered) == len(set(rendered)), "a type has two cases"
    assert set(rendered) == {t.value for t in EventType}


def test_every_event_type_the_page_tests_for_exists() -> None:
    tested = re.findall(r'\be\.type\s*[!=]==?\s*"(\w+)"', APP_JS.read_text("utf-8"))
    assert tested, "the page no longer tests e.type; update this test"
    assert set(tested) <= {t.value for t in EventType}
