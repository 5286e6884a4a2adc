"""Error lines keep every character of the message, brackets included."""

from __future__ import annotations

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

    from explaindrive.cli.main import app

    runner = CliRunner()
    assert "Longest ride [s]." in runner.invoke(app, ["ride", "--help"]).output
    assert "Stop injections [s], e.g. 60-75,150-165." in " ".join(
        runner.invoke(app, ["evaluate", "--help"]).output.split()
    )
