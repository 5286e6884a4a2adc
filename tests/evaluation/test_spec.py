"""Grid and schedule parsing: valid texts and clear errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from explaindrive.evaluation.paper import PAPER_MERGED_COMMANDS
from explaindrive.evaluation.spec import (
    PolicySpec,
    SpecError,
    build_grid,
    parse_commands,
    parse_levels,
    parse_policy,
    parse_seeds,
    parse_stop_schedule,
    plan_run,
    segments_to_schedule,
    stops_to_schedule,
)

FAST = PolicySpec("fast", "agent", ("fast.pt",), "agent", "fast")
MERGED = PolicySpec("merged", "merged", ("f.pt", "c.pt"), "agent", "fast")


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


def test_grid_is_level_major_and_checks_commands() -> None:
    grid = build_grid(FAST, (0, 1), (0.5, 1.0), max_steps=30)
    assert [(e.traffic_level, e.seed) for e in grid] == [(0.5, 0), (0.5, 1), (1.0, 0), (1.0, 1)]
    assert all(e.command == "fast" and e.max_steps == 30 for e in grid)
    with pytest.raises(SpecError, match="drives only under fast, stop"):
        build_grid(FAST, (0,), (1.0,), schedule=((10.0, "comfort"),))
    with pytest.raises(SpecError, match="empty"):
        build_grid(FAST, (), (1.0,))
    with pytest.raises(SpecError, match="max_steps"):
        build_grid(FAST, (0,), (1.0,), max_steps=0)


def test_plan_names_and_defaults() -> None:
    assert plan_run(FAST, (0,), (1.0,)).name == "fast"
    stops = plan_run(FAST, (0,), (1.0,), stop_schedule="60-75")
    assert stops.name == "fast + stops" and stops.stop_intervals == ((60.0, 75.0),)
    assert stops.episodes[0].schedule == ((60.0, "stop"), (75.0, "fast"))
    merged = plan_run(MERGED, (0,), (1.0,))
    assert merged.name == "merged" and merged.stop_intervals == ((90.0, 110.0),)
    assert merged.episodes[0].schedule == ((90.0, "stop"), (110.0, "comfort"))
    with pytest.raises(SpecError, match="not both"):
        plan_run(FAST, (0,), (1.0,), stop_schedule="60-75", commands="fast:0-")


def test_policy_resolution(tmp_path: Path) -> None:
    assert parse_policy("krauss").kind == "baseline"
    assert parse_policy("IDM").ego_model == "idm"
    with pytest.raises(SpecError, match="policy file not found"):
        parse_policy(str(tmp_path / "nope.pt"))
    with pytest.raises(SpecError, match="not found"):
        parse_policy("fast", fast_path=tmp_path / "missing.pt")
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "policy.pt").write_bytes(b"")
    (tmp_path / "run" / "policy.json").write_text('{"mode": "comfort"}')
    spec = parse_policy(str(tmp_path / "run"))
    assert (spec.name, spec.primary, spec.kind) == ("run", "comfort", "agent")


def test_a_noisy_run_names_its_noise_and_every_episode_carries_it() -> None:
    plan = plan_run(FAST, (0, 1), (0.5,), obs_noise=(2.0, 0.6))
    assert plan.name == "fast, noise 2 m / 0.6 m/s"
    assert {e.obs_noise for e in plan.episodes} == {(2.0, 0.6)}
    assert plan_run(FAST, (0,), (0.5,)).episodes[0].obs_noise == (0.0, 0.0)
