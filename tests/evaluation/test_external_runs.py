"""Drivers evaluated elsewhere (a Stable-Baselines3 model) in the report's tables."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from explaindrive.evaluation.report import external_runs, run_report
from explaindrive.evaluation.report_plan import plan_report
from explaindrive.evaluation.runner import EpisodeRecord, run_grid
from explaindrive.evaluation.schema import read_runs, run_document, write_json
from explaindrive.evaluation.spec import parse_policy, plan_run

MAX_STEPS = 25  # [steps] short episodes keep the suite fast
DOC = {"schema": "explaindrive-evaluation"}


@pytest.fixture(scope="module")
def krauss_records() -> list[EpisodeRecord]:
    plan = plan_run(parse_policy("krauss"), (0,), (0.5,), max_steps=MAX_STEPS)
    return run_grid(plan.episodes, workers=1)


def test_an_evaluation_file_is_read_back_as_written(
    tmp_path: Path, krauss_records: list[EpisodeRecord]
) -> None:
    path = write_json(tmp_path / "e.json", [run_document("other", krauss_records)])
    (run,) = read_runs(path)
    assert run.name == "other" and run.policy["name"] == "krauss"
    assert run.episodes == ((0.5, 0, krauss_records[0].result),)


def test_an_external_run_joins_the_report_tables(
    tmp_path: Path, krauss_records: list[EpisodeRecord]
) -> None:
    path = write_json(tmp_path / "sb3.json", [run_document("sb3-ppo", krauss_records)])
    plan = plan_report(["krauss"], (0,), (0.5,), max_steps=MAX_STEPS)
    stored = external_runs(plan, [path])
    assert list(stored) == ["sb3-ppo"]
    md = run_report(plan, tmp_path / "results.md", workers=1, external=stored).markdown
    assert f"- **sb3-ppo**: evaluated outside the report, read from `{path}`" in md
    # the same episode as the report's own krauss run: the same mean speed in each table
    speed = f"{krauss_records[0].result.mean_speed_mps:.3f}"
    rows = [line for line in md.splitlines() if line.startswith("| sb3-ppo")]
    assert len(rows) >= 3 and all(speed in row for row in rows[:2])


def test_an_external_run_must_lie_on_the_grid_under_a_name_of_its_own(
    tmp_path: Path, krauss_records: list[EpisodeRecord]
) -> None:
    path = write_json(tmp_path / "k.json", [run_document("krauss", krauss_records)])
    plan = plan_report(["krauss"], (0,), (0.5,), max_steps=MAX_STEPS)
    with pytest.raises(ValueError, match="run 'krauss' has the name of another run"):
        external_runs(plan, [path])
    path = write_json(tmp_path / "o.json", [run_document("other", krauss_records)])
    wider = plan_report(["krauss"], (0, 1), (0.5,), max_steps=MAX_STEPS)
    with pytest.raises(ValueError, match=r"run 'other' is not on the report's grid \(seeds"):
        external_runs(wider, [path])


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "evaluation file not found"),
        ("{not json", "is not JSON"),
        (json.dumps({"schema": "other"}), "is not an explaindrive-evaluation file"),
        (json.dumps({**DOC, "runs": []}), "holds no runs"),
        (json.dumps({**DOC, "runs": [{"name": "x", "episodes": []}]}), "run 'x' has no episodes"),
        (json.dumps({**DOC, "runs": [{"name": "x", "episodes": [{"seed": 0}]}]}), "run 0 cannot"),
    ],
)
def test_a_bad_evaluation_file_is_named(tmp_path: Path, content: str | None, message: str) -> None:
    path = tmp_path / "bad.json"
    if content is not None:
        path.write_text(content)
    with pytest.raises(ValueError, match=message):
        read_runs(path)
