"""Evaluating over scenarios: held-out generated ones, repeated grids, grouping."""

from __future__ import annotations

from pathlib import Path

import pytest

from explaindrive.evaluation.parsing import SpecError
from explaindrive.evaluation.scenarios import over_scenarios, parse_scenarios
from explaindrive.evaluation.spec import parse_policy, plan_run


def test_held_out_scenarios_repeat_the_grid(tmp_path: Path) -> None:
    cases = parse_scenarios("random:100-101", tmp_path)
    assert [c.name for c in cases] == ["random-100", "random-101"]
    plan = plan_run(parse_policy("krauss"), (0, 1), (1.0,))
    episodes = over_scenarios(plan, cases).episodes
    assert [(e.scenario_name, e.seed) for e in episodes] == [
        ("random-100", 0), ("random-100", 1), ("random-101", 0), ("random-101", 1)
    ]  # fmt: skip
    directory = Path(dict(episodes[0].scenario)["scenario"])
    assert (directory / "scenario.yaml").is_file() and directory.parent == tmp_path / "scenarios"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("grid:1", "must look like random:SEEDS"),
        ("random:5-3", "seed range '5-3' is reversed"),
        ("random:1000000", r"scenario seed\(s\) \[1000000\] are not held out"),
    ],
)
def test_bad_scenario_lists_are_named(text: str, message: str, tmp_path: Path) -> None:
    with pytest.raises(SpecError, match=message):
        parse_scenarios(text, tmp_path)
