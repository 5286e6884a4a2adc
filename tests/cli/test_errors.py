"""Error lines keep every character of the message, brackets included."""

from __future__ import annotations

from pathlib import Path

import pytest
import typer
from rich.console import Console

from explaindrive.cli._errors import error_line


def test_brackets_in_a_message_are_printed_not_read_as_markup() -> None:
    console = Console(record=True, width=200, color_system=None)
    message = "install it with `pip install 'explaindrive[ray]'`; Input should be 1 [type=int_type]"
    console.print(error_line(message))
    assert console.export_text() == f"error: {message}\n"
    console.print(error_line(ValueError("[bold]not a style[/bold]")))
    assert console.export_text().endswith("error: [bold]not a style[/bold]\n")


def test_help_shows_the_units_in_brackets() -> None:
    from typer.testing import CliRunner

    from explaindrive.cli.app import app

    runner = CliRunner()
    assert "Longest ride [s]." in runner.invoke(app, ["ride", "--help"]).output
    assert "Stop injections [s], e.g. 60-75,150-165." in " ".join(
        runner.invoke(app, ["evaluate", "--help"]).output.split()
    )


def test_error_lines_go_to_stderr_and_refuse_exits_with_the_code(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from explaindrive.cli import _errors

    with pytest.raises(typer.Exit) as exit_info:
        _errors.refuse("no such file: x.yaml", code=3)
    assert exit_info.value.exit_code == 3
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == "error: no such file: x.yaml\n"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["scenario", "plot", "--net", "missing.net.xml", "--out", "n.png"], "network file"),
        (["scenario", "build", "--set", "lanes=2"], "--set needs --out DIR"),
        (["interpret"], "give either TEXT or --audio FILE"),
        (["transcribe", "missing.wav"], "missing.wav"),
        (["demo", "--command", "faster"], "faster"),
    ],
)
def test_every_subcommand_writes_its_error_on_stderr(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, args: list[str], message: str
) -> None:
    from typer.testing import CliRunner

    from explaindrive.cli.app import app

    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output
    assert result.stdout == ""
    assert result.stderr.startswith("error: ") and message in result.stderr
