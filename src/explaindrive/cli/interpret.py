"""``explaindrive interpret "TEXT"``: LLM-1, a request to a command and its confirmation."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

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


def interpret_command(
    text: Annotated[str | None, typer.Argument(help="The passenger's request.")] = None,
    audio: Annotated[Path | None, typer.Option("--audio", help="Transcribe this file.")] = None,
    backend: Annotated[str | None, typer.Option("--backend", help=BACKEND_HELP)] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    config: Annotated[Path | None, typer.Option("--config", help=CONFIG_HELP)] = None,
    model: Annotated[str | None, typer.Option("--model", help=MODEL_HELP)] = None,
) -> None:
    """Map a passenger request (text or --audio) to fast, comfort, stop or no command."""
    from explaindrive.language.speech.transcriber import AudioError

    if (text is None) == (audio is None):
        fail("give either TEXT or --audio FILE")
    try:
        from explaindrive.language.stack import make_language_stack

        stack = make_language_stack(backend, load_config(config, model)).load()
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))
    transcript = None
    if audio is not None:
        try:
            transcript = stack.transcriber.transcribe(audio)
        except (AudioError, FileNotFoundError) as exc:
            fail(str(exc))
        text = transcript.text
    assert text is not None
    result = stack.interpreter.interpret(text)
    out = {**result.to_json(), "latency_s": round(result.latency_s, 4), "error": result.error}
    if transcript is not None:
        out["transcript"] = transcript.text
    if as_json:
        emit_json(out)
        return
    if transcript is not None:
        console.print(f"[dim]heard:[/] {transcript.text}", highlight=False)
    intent = out["intent"] or "none"
    if result.intent is None and result.reading not in (None, "none"):
        intent = f"none (reading: {result.reading})"  # a why question or a yes / no answer
    if result.ask is not None:
        intent = f"none (asks whether to {result.ask.label})"  # STOP most probable, unsure
    note = " [yellow](fallback)[/]" if result.fallback else ""
    note += " [dim](offline STOP check)[/]" if result.stop_lane else ""
    console.print(f"[bold]{intent}[/] via {result.backend}{note}", highlight=False)
    console.print(str(result.confirmation), highlight=False)


def register(app: typer.Typer) -> None:
    """Add ``interpret`` to the root command."""
    app.command("interpret")(interpret_command)
