"""``explaindrive report``: regenerate ``docs/results.md`` and its figures."""

from __future__ import annotations

import typer


def register(app: typer.Typer) -> None:
    """Add ``report`` to the CLI."""
