"""``explaindrive serve`` refuses bad names before a server starts."""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from explaindrive.cli import serve
from explaindrive.language import encoders

app = typer.Typer()
serve.register(app)
app.command("noop")(lambda: None)  # two commands, so Typer keeps the sub-command name
runner = CliRunner()


def test_unknown_backend_exits_before_serving() -> None:
    res = runner.invoke(app, ["serve", "--backend", "gpt"])
    assert res.exit_code == 2
    assert "unknown language backend 'gpt'" in res.output


def test_unknown_encoder_exits_before_serving() -> None:
    res = runner.invoke(app, ["serve", "--encoder", "bert"])
    assert res.exit_code == 2
    assert "unknown sentence encoder 'bert'" in res.output


def test_an_encoder_that_is_not_installed_exits_before_serving(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def missing(name: str) -> metadata.Distribution:
        raise metadata.PackageNotFoundError(name)

    monkeypatch.setattr(encoders.metadata, "distribution", missing)
    monkeypatch.setenv("EXPLAINDRIVE_CACHE", str(tmp_path))  # mpnet not extracted there
    res = runner.invoke(app, ["serve", "--encoder", "mpnet"])
    assert res.exit_code == 2 and "[mpnet]" in res.output
