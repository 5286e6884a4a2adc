"""``explaindrive score ...``: the command group that scores the language layer on labelled
data (its commands are added by :mod:`explaindrive.cli.eval_language`)."""

from __future__ import annotations

import typer

score_app = typer.Typer(
    name="score",
    help="Score the language layer on labelled data.",
    no_args_is_help=True,
    add_completion=False,
)


def register(app: typer.Typer) -> None:
    """Mount the ``score`` group on the root command."""
    app.add_typer(score_app, name="score")
