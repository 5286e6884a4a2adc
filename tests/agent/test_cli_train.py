"""``explaindrive train`` argument handling (no training: only refusals and config)."""

from __future__ import annotations

from pathlib import Path

import typer
from typer.testing import CliRunner

from explaindrive.cli.train import register, resolve_config


def _app() -> typer.Typer:
    app = typer.Typer()
    register(app)

    @app.callback()
    def _root() -> None:  # keep ``train`` a subcommand
        pass

    return app


def test_unknown_mode_is_refused(tmp_path: Path) -> None:
    result = CliRunner().invoke(_app(), ["train", "--mode", "sporty", "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert "unknown mode 'sporty'" in result.output
    assert not (tmp_path / "episodes.csv").exists()


def test_unknown_override_key_is_refused(tmp_path: Path) -> None:
    args = ["train", "--mode", "fast", "--set", "learning_rate=1", "--out", str(tmp_path)]
    result = CliRunner().invoke(_app(), args)
    assert result.exit_code == 2 and "learning_rate" in result.output


def test_flags_override_preset_and_resume_reuses_the_saved_config(tmp_path: Path) -> None:
    c = resolve_config("comfort", "paper", None, ["batch_size=32"], tmp_path, False,
                       episodes=7, num_envs=2, seed=None)  # fmt: skip
    assert (c.mode, c.episodes, c.num_envs, c.batch_size, c.lr) == ("comfort", 7, 2, 32, 1e-3)
    (tmp_path / "config.json").write_text(c.to_json())
    resumed = resolve_config("comfort", None, None, [], tmp_path, True, episodes=9)
    assert (resumed.batch_size, resumed.episodes, resumed.num_envs) == (32, 9, 2)
