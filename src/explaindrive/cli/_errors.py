"""One way to print an error line on a Rich console."""

from __future__ import annotations

from rich.console import Console
from rich.markup import escape


def error_line(message: object) -> str:
    """``error: <message>`` in red, the message escaped so that brackets in it (an extra such
    as ``.[ray]``, pydantic's ``[type=...]``) are printed instead of read as Rich markup."""
    return f"[red]error:[/red] {escape(str(message))}"


def print_error(console: Console, message: object) -> None:
    """Print :func:`error_line` as one line, however narrow the terminal (no wrapping)."""
    console.print(error_line(message), soft_wrap=True, highlight=False)
