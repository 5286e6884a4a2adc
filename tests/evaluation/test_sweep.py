"""Training seeds side by side: the per-run options and the combined table."""

from __future__ import annotations

import json
from pathlib import Path

from explaindrive.cli.train import seed_run_args
from explaindrive.evaluation.sweep import evaluate_seeds, seed_run_dir
from tests.helpers import constant_policy


def test_every_seed_run_gets_the_same_options() -> None:
    args = seed_run_args("fast", 200, 2, True, "paper", Path("c.yaml"), ["lr=3e-4"], True, None)
    assert args == ["--mode", "fast", "--episodes", "200", "--envs", "2", "--preset", "paper",
                    "--config", "c.yaml", "--set", "lr=3e-4", "--resume", "--ray"]  # fmt: skip
    assert seed_run_args("comfort", None, None, False, None, None, [], False, "h:1") == [
        "--mode", "comfort", "--ray-address", "h:1",
    ]  # fmt: skip


def _constant_run(out: Path, seed: int, action: int) -> None:
    constant_policy(seed_run_dir(out, seed) / "policy.pt", action, {"name": "fast", "mode": "fast"})


def test_finished_seeds_are_evaluated_into_one_table(tmp_path: Path) -> None:
    _constant_run(tmp_path, 0, 3)  # always idle: stands at the entry
    _constant_run(tmp_path, 1, 6)  # always +3 m/s: speeds
    # seed 2 never finished (no policy.pt): it is left out
    results = evaluate_seeds(tmp_path, [0, 1, 2], [0], [1.0], None, workers=1)
    assert [Path(r.run).name for r in results] == ["seed-0", "seed-1"]
    assert results[0].overall.mean_speed_mps == 0.0 and results[0].shield_share == 0.0
    assert results[1].overall.speeding_steps > 0 and results[1].shield_share > 0.5
    table = (tmp_path / "seeds.md").read_text()
    assert "bare networks, seeds 0-0 x traffic 1.0" in table and "| spread (std) |" in table
    doc = json.loads((tmp_path / "seeds.json").read_text())
    assert [Path(d["run"]).name for d in doc] == ["seed-0", "seed-1"]


def test_seeds_trained_by_an_earlier_command_keep_their_row(tmp_path: Path) -> None:
    _constant_run(tmp_path, 0, 3)  # trained by an earlier `--seeds 0` into the same folder
    _constant_run(tmp_path, 1, 3)
    (tmp_path / "seed-notes").mkdir()  # not a seed folder
    results = evaluate_seeds(tmp_path, [1], [0], [1.0], None, workers=1)
    assert [Path(r.run).name for r in results] == ["seed-0", "seed-1"]
    doc = json.loads((tmp_path / "seeds.json").read_text())
    assert [Path(d["run"]).name for d in doc] == ["seed-0", "seed-1"]
