"""``explaindrive eval ...``: a sub-command group other modules add evaluations to."""

from __future__ import annotations

import typer

eval_app = typer.Typer(
    name="eval", help="Quantitative evaluations.", no_args_is_help=True, add_completion=False
)


def register(app: typer.Typer) -> None:
    """Mount the ``eval`` group on the root command."""
    app.add_typer(eval_app, name="eval")
