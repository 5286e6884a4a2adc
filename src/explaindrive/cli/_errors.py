"""The one way a command reports an error: one line on stderr.

Every subcommand prints its errors with :func:`print_error` (or ends with :func:`refuse`),
so stdout keeps only a command's results and a script can tell the two apart.
"""

from __future__ import annotations

from typing import NoReturn

import typer
from rich.console import Console
from rich.markup import escape

err_console = Console(stderr=True, soft_wrap=True)
"""The console every error line goes to (stderr; a line never wraps)."""


def error_line(message: object) -> str:
    """``error: <message>`` in red, the message escaped so that brackets in it (an extra such
    as ``.[ray]``, pydantic's ``[type=...]``) are printed instead of read as Rich markup."""
    return f"[red]error:[/red] {escape(str(message))}"


def print_error(message: object) -> None:
    """Print :func:`error_line` on stderr as one line, however narrow the terminal."""
    err_console.print(error_line(message), soft_wrap=True, highlight=False)


def refuse(message: object, code: int = 2) -> NoReturn:
    """Print :func:`error_line` on stderr and end the command with exit status ``code``."""
    print_error(message)
    raise typer.Exit(code)
