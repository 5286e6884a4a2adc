"""``explaindrive explain --case FILE.json``: LLM-2 decision and LLM-3 explanation."""

from __future__ import annotations

import contextlib
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from explaindrive.cli._language_common import (
    BACKEND_HELP,
    CONFIG_HELP,
    MODEL_HELP,
    console,
    emit_json,
    fail,
    load_config,
)

if TYPE_CHECKING:
    from explaindrive.language.explanation.summary import StateRecord


def explain_command(
    case: Annotated[Path, typer.Option("--case", help="State record JSON file.")],
    backend: Annotated[str | None, typer.Option("--backend", help=BACKEND_HELP)] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    config: Annotated[Path | None, typer.Option("--config", help=CONFIG_HELP)] = None,
    model: Annotated[str | None, typer.Option("--model", help=MODEL_HELP)] = None,
) -> None:
    """Decide whether a step's action needs explaining and, if so, explain it."""
    from explaindrive.language.explanation.summary import environment_summary

    try:
        record = read_case(case)
        from explaindrive.language.stack import make_language_stack

        stack = make_language_stack(backend, load_config(config, model))
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))
    try:  # the modules answer every reply; a failure anywhere is one line, not a traceback
        decision = stack.decider.decide(record)
        explanation = stack.explainer.explain(record, decision.factor) if decision.explain else None
    except Exception as exc:
        fail(f"could not decide or explain {case}: {type(exc).__name__}: {exc}", code=1)
    errors = [e.error for e in (decision, explanation) if e is not None and e.error]
    out = {
        "explain": decision.explain,
        "factor": decision.factor.value if decision.factor else None,
        "text": explanation.text if explanation is not None else None,
        "backend": stack.backend,
        "fallback": decision.fallback or (explanation is not None and explanation.fallback),
        "vetoed": decision.vetoed,  # a remote [EXPLAIN] the state does not bear out
        "errors": errors,  # why the remote model was bypassed (a rejected reply says why)
    }
    if as_json:
        emit_json(out)
        return
    console.print(f"[dim]{environment_summary(record)}[/]", highlight=False)
    console.print(f"[bold]{decision.tag}[/] ({decision.reason})", highlight=False)
    if explanation is not None:
        console.print(explanation.text, highlight=False)


def read_case(path: Path) -> StateRecord:
    """The state record in ``path``; every number in it must be finite.

    Raises:
        FileNotFoundError: if the file does not exist.
        ValueError: naming the file, if it is not UTF-8, not JSON, holds NaN or an
            infinity, or is not a valid record.
    """
    if not path.is_file():
        raise FileNotFoundError(f"state record file not found: {path}")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not UTF-8 text (byte {exc.start}: {exc.reason})") from exc
    _check_finite(text, str(path))
    from explaindrive.language.explanation.summary import StateRecord

    return StateRecord.from_json(text, source=str(path))


def _check_finite(text: str, source: str) -> None:
    """Refuse ``NaN``, ``Infinity`` and numbers too large for a float in JSON ``text``."""

    def constant(name: str) -> float:
        raise ValueError(f"{source}: {name} is not allowed; give a finite number, or null")

    def number(literal: str) -> float:
        value = float(literal)
        if not math.isfinite(value):
            raise ValueError(f"{source}: {literal[:40]} is not a finite number")
        return value

    with contextlib.suppress(json.JSONDecodeError):  # from_json says where JSON is malformed
        json.loads(text, parse_constant=constant, parse_float=number)


def register(app: typer.Typer) -> None:
    """Add ``explain`` to the root command."""
    app.command("explain")(explain_command)
