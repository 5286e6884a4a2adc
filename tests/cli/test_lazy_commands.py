"""The root command lists its commands without importing them, and each loads on use."""

from __future__ import annotations

import subprocess
import sys

import pytest
import typer

from explaindrive.cli.app import COMMANDS, load_command


@pytest.mark.parametrize("name", list(COMMANDS))
def test_the_listed_help_is_the_command_s_own(name: str) -> None:
    command = load_command(name)
    assert command.name == name
    assert (command.help or "").split("\n\n")[0].strip() == COMMANDS[name][1]


def test_the_root_help_imports_no_command() -> None:
    code = (
        "import sys; from explaindrive.cli.entry import main; sys.argv = ['x', '--help']\n"
        "try:\n    main()\nexcept SystemExit:\n    pass\n"
        "print(sorted(m for m in sys.modules if m.startswith('explaindrive.cli.')"
        " and m.rsplit('.', 1)[1] in " + repr(sorted(COMMANDS)) + "))\n"
        "print(sorted(m for m in ('torch', 'gymnasium', 'matplotlib', 'pydantic', 'numpy')"
        " if m in sys.modules))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.splitlines()[-2:] == ["[]", "[]"]


def test_a_mistyped_command_is_answered_with_the_close_ones() -> None:
    from typer.testing import CliRunner

    from explaindrive.cli.app import app

    result = CliRunner().invoke(app, ["traiin"])
    assert result.exit_code == 2
    assert "No such command 'traiin'. Did you mean 'train'?" in result.output
    assert isinstance(typer.main.get_command(app), typer.core.TyperGroup)
