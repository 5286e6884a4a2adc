"""The text formats of grids and schedules: valid texts and clear errors."""

from __future__ import annotations

import pytest

from explaindrive.evaluation.paper import PAPER_MERGED_COMMANDS
from explaindrive.evaluation.parsing import (
    SpecError,
    parse_commands,
    parse_levels,
    parse_seeds,
    parse_stop_schedule,
    segments_to_schedule,
    stops_to_schedule,
)


def test_seed_lists() -> None:
    assert parse_seeds("0-4") == (0, 1, 2, 3, 4)
    assert parse_seeds("7, 3,0") == (7, 3, 0)
    assert parse_seeds("0-2,10") == (0, 1, 2, 10)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty"),
        ("a", "not an integer"),
        ("-1", "outside"),
        ("2147483648", "outside"),
        ("4-0", "reversed"),
        ("0-2,1", "repeats"),
        ("0,,1", "empty entry"),
    ],
)
def test_bad_seeds(text: str, message: str) -> None:
    with pytest.raises(SpecError, match=message):
        parse_seeds(text)


def test_a_seed_list_holds_at_most_a_thousand_seeds() -> None:
    assert len(parse_seeds("0-999")) == 1000
    assert len(parse_seeds("0-499,1000-1499")) == 1000
    with pytest.raises(SpecError, match="names 1001 or more seeds; at most 1000 in a run"):
        parse_seeds("0-1000")
    with pytest.raises(SpecError, match="names 1001 or more seeds"):
        parse_seeds("0-999,5000")
    with pytest.raises(SpecError, match="names 100000000 or more seeds"):
        parse_seeds("0-99999999")  # refused before the range is expanded


def test_levels() -> None:
    assert parse_levels("0.5,0.75,1.0,1.25,1.5") == (0.5, 0.75, 1.0, 1.25, 1.5)
    for text, message in [("x", "not a number"), ("0", "> 0"), ("-1", "> 0"),
                          ("nan", "finite"), ("1,1.0", "repeats"),
                          ("2.1", "at most 2, got 2.1")]:  # fmt: skip
        with pytest.raises(SpecError, match=message):
            parse_levels(text)


def test_stop_schedule() -> None:
    intervals = parse_stop_schedule("60-75,150-165")
    assert intervals == ((60.0, 75.0), (150.0, 165.0))
    assert stops_to_schedule("comfort", intervals) == (
        (60.0, "stop"), (75.0, "comfort"), (150.0, "stop"), (165.0, "comfort"),
    )  # fmt: skip
    assert stops_to_schedule("fast", parse_stop_schedule("30-")) == ((30.0, "stop"),)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("75-60", "ends before it starts"),
        ("60", "START-END"),
        ("60-75,70-80", "must not overlap"),
        ("150-165,60-75", "in order"),
        ("60-,100-110", "only the last"),
        ("a-b", "not a number"),
        ("-5-3", "START-END"),
    ],
)
def test_bad_stop_schedules(text: str, message: str) -> None:
    with pytest.raises(SpecError, match=message):
        parse_stop_schedule(text)


def test_commands() -> None:
    segments = parse_commands(PAPER_MERGED_COMMANDS)
    assert segments == (("fast", 0.0, 90.0), ("stop", 90.0, 110.0), ("comfort", 110.0, None))
    assert segments_to_schedule(segments) == ("fast", ((90.0, "stop"), (110.0, "comfort")))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("fast:5-", "must start at 0"),
        ("fast:0-90,comfort:100-", "contiguous"),
        ("fast:0-90,comfort:80-", "contiguous"),
        ("fast:0-90", "open-ended"),
        ("speedy:0-", "unknown command"),
        ("fast0-", "COMMAND:START-END"),
    ],
)
def test_bad_commands(text: str, message: str) -> None:
    with pytest.raises(SpecError, match=message):
        parse_commands(text)
