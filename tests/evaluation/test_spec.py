"""Policies, grids and run plans: what a run evaluates, and clear errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from explaindrive.evaluation.parsing import SpecError
from explaindrive.evaluation.spec import PolicySpec, build_grid, parse_policy, plan_run

FAST = PolicySpec("fast", "agent", ("fast.pt",), "agent", "fast")
MERGED = PolicySpec("merged", "merged", ("f.pt", "c.pt"), "agent", "fast")


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
