"""The ``explaindrive`` command group: assembles the per-command modules, each loaded on use.

The program lists its commands from :data:`COMMANDS` without importing them; a command's
module (and what it imports) is loaded only when that command runs or shows its help, so
``explaindrive --help`` needs typer alone. The program around it (signals, one-line
errors) is :mod:`explaindrive.cli.entry`.
"""

from __future__ import annotations

import importlib
import logging
from difflib import get_close_matches

import typer
from typer._click import Command, Context, HelpFormatter
from typer._click.exceptions import UsageError
from typer._click.utils import make_default_short_help
from typer.core import TyperGroup

from explaindrive.redact import RedactingFilter

# name: (module exposing ``register(app)``, the first paragraph of the command's help).
# The help is written here so that listing the commands imports none of them; a test checks
# it against each command's own docstring.
COMMANDS: dict[str, tuple[str, str]] = {
    "demo": (
        "explaindrive.cli.demo",
        "Drive one episode with the cautious rule-based driver and print its figures.",
    ),
    "train": (
        "explaindrive.cli.train",
        "Train a D3QN driving agent with the paper's command schedule.",
    ),
    "evaluate": (
        "explaindrive.cli.evaluate",
        "Evaluate a policy or a SUMO baseline; prints Markdown tables in the paper's layout.",
    ),
    "report": (
        "explaindrive.cli.report",
        "Evaluate the policies and baselines and rewrite the results document and figures.",
    ),
    "ride": (
        "explaindrive.cli.ride",
        "Ride in the simulated car: ask for fast, comfort or stop; watch it drive and explain.",
    ),
    "interpret": (
        "explaindrive.cli.interpret",
        "Map a passenger request (text or --audio) to fast, comfort, stop or no command.",
    ),
    "explain": (
        "explaindrive.cli.explain",
        "Decide whether a step's action needs explaining and, if so, explain it.",
    ),
    "transcribe": (
        "explaindrive.cli.transcribe",
        "Transcribe a spoken request with Whisper (tiny.en, offline).",
    ),
    "serve": (
        "explaindrive.cli.serve",
        "Serve the passenger page: watch the ride, talk to the car, read its explanations.",
    ),
    "scenario": ("explaindrive.cli.scenario", "Build or draw urban SUMO scenarios."),
    "score": ("explaindrive.cli.score", "Score the language layer on labelled data."),
}


def load_command(name: str) -> Command:
    """The click command ``name``, built from its module's ``register(app)``."""
    module, _ = COMMANDS[name]
    holder = typer.Typer(add_completion=False, pretty_exceptions_enable=False,
                         rich_markup_mode=None)  # fmt: skip
    importlib.import_module(module).register(holder)
    command = typer.main.get_group(holder).commands[name]
    return command


class LazyGroup(TyperGroup):
    """The root group: commands known by name, each module imported on first use."""

    def list_commands(self, ctx: Context) -> list[str]:
        return list(COMMANDS)

    def get_command(self, ctx: Context, cmd_name: str) -> Command | None:
        if cmd_name not in COMMANDS:
            return None
        if cmd_name not in self.commands:
            self.commands[cmd_name] = load_command(cmd_name)
        return self.commands[cmd_name]

    def resolve_command(
        self, ctx: Context, args: list[str]
    ) -> tuple[str | None, Command | None, list[str]]:
        try:
            return super().resolve_command(ctx, args)
        except UsageError as exc:  # the suggestion names commands not loaded yet
            matches = get_close_matches(args[0], list(COMMANDS)) if args else []
            if matches and "Did you mean" not in exc.message:
                suggestions = ", ".join(f"{m!r}" for m in matches)
                exc.message = f"{exc.message.rstrip('.')}. Did you mean {suggestions}?"
            raise

    def format_commands(self, ctx: Context, formatter: HelpFormatter) -> None:
        limit = formatter.width - 6 - max(len(name) for name in COMMANDS)
        rows = [
            (name, make_default_short_help(text, limit)) for name, (_, text) in COMMANDS.items()
        ]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


app = typer.Typer(
    name="explaindrive",
    cls=LazyGroup,
    help="Passenger-directed, explainable autonomous driving in SUMO.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help text as written: "[s]" is a unit, not Rich markup
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
