"""``explaindrive explain --case FILE.json``: LLM-2 decision and LLM-3 explanation."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from explaindrive.cli._language_common import (
    BACKEND_HELP,
    CONFIG_HELP,
    console,
    emit_json,
    fail,
    load_config,
)
from explaindrive.language.summary import StateRecord, environment_summary


def explain_command(
    case: Annotated[Path, typer.Option("--case", help="State record JSON file.")],
    backend: Annotated[str | None, typer.Option("--backend", help=BACKEND_HELP)] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    config: Annotated[Path | None, typer.Option("--config", help=CONFIG_HELP)] = None,
) -> None:
    """Decide whether a step's action needs explaining and, if so, explain it."""
    try:
        record = StateRecord.load(case)
        from explaindrive.language.stack import make_language_stack

        stack = make_language_stack(backend, load_config(config))
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))
    decision = stack.decider.decide(record)
    text = None
    fallback = decision.fallback
    if decision.explain:
        explanation = stack.explainer.explain(record, decision.factor)
        text = explanation.text
        fallback = fallback or explanation.fallback
    out = {
        "explain": decision.explain,
        "factor": decision.factor.value if decision.factor else None,
        "text": text,
        "backend": stack.backend,
        "fallback": fallback,
    }
    if as_json:
        emit_json(out)
        return
    console.print(f"[dim]{environment_summary(record)}[/]", highlight=False)
    console.print(f"[bold]{decision.tag}[/] ({decision.reason})", highlight=False)
    if text:
        console.print(text, highlight=False)


def register(app: typer.Typer) -> None:
    """Add ``explain`` to the root command."""
    app.command("explain")(explain_command)
