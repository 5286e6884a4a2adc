"""The training-seed table against numbers computed by hand."""

from __future__ import annotations

from explaindrive.evaluation.aggregate import aggregate
from explaindrive.evaluation.seeds import SeedResult, seed_table
from tests.evaluation.test_aggregate import result


def _run(name: str, speed: float, collided: bool, overrides: int) -> SeedResult:
    episodes = [result(mean_speed_mps=speed, collisions=int(collided))] * 2
    agg = aggregate(episodes)
    return SeedResult(name, agg, sum(e.steps for e in episodes), overrides)


def test_seed_table_lists_each_run_then_mean_and_spread() -> None:
    runs = [_run("s0", 8.0, False, 0), _run("s1", 6.0, True, 4)]
    lines = seed_table(runs).splitlines()
    assert lines[0].startswith("| run | episodes | collisions |")
    assert len(lines) == 2 + 2 + 2  # header, rule, two runs, mean, spread
    cells = [line.split(" | ") for line in lines[2:]]
    assert cells[0][2] == "0" and cells[1][2] == "2"  # collision episodes
    assert lines[0].split(" | ")[5] == "yield viol."
    assert cells[0][8] == "8.000" and cells[1][8] == "6.000"  # mean speed
    assert cells[2][2] == "1.000" and cells[2][8] == "7.000"  # means
    assert cells[3][2] == "1.000" and cells[3][8] == "1.000"  # population std
    steps = runs[1].steps
    assert cells[1][-1].rstrip(" |") == f"{100 * 4 / steps:.3f}"


def test_report_includes_seed_tables_under_their_run_folder(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from explaindrive.evaluation.report_sections import seeds_section

    table = tmp_path / "fast-seeds" / "seeds.md"
    table.parent.mkdir()
    table.write_text("# Training seeds: bare networks, seeds 1000-1009\n\n| run |\n| --- |\n")
    text = seeds_section([table])
    assert "## Training seeds" in text
    assert "### fast-seeds: bare networks, seeds 1000-1009\n\n| run |\n| --- |\n" in text
    assert seeds_section([]) == ""
