"""The ``explaindrive`` command: assembles the per-command modules."""

from __future__ import annotations

import importlib
import logging

import typer

from explaindrive.redact import RedactingFilter

app = typer.Typer(
    name="explaindrive",
    help="Passenger-directed, explainable autonomous driving in SUMO.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help text as written: "[s]" is a unit, not Rich markup
)

# Each module exposes ``register(app)``; one line per command module.
_COMMAND_MODULES: tuple[str, ...] = (
    "explaindrive.cli.demo",
    "explaindrive.cli.scenario",
    "explaindrive.cli.train",
    "explaindrive.cli.evaluate",
    "explaindrive.cli.report",
    "explaindrive.cli.ride",
    "explaindrive.cli.interpret",
    "explaindrive.cli.explain",
    "explaindrive.cli.transcribe",
    "explaindrive.cli.score",
    "explaindrive.cli.serve",
)


@app.callback()
def _root(verbose: bool = typer.Option(False, "--verbose", "-v", help="Debug logging.")) -> None:
    logging.basicConfig(
        level=logging.DEBUG if verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    for handler in logging.getLogger().handlers:  # keys never reach a log line
        if not any(isinstance(f, RedactingFilter) for f in handler.filters):
            handler.addFilter(RedactingFilter())


for _name in _COMMAND_MODULES:
    importlib.import_module(_name).register(app)


if __name__ == "__main__":  # pragma: no cover
    from explaindrive.cli.entry import main

    main()
