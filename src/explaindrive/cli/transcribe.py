"""``explaindrive transcribe FILE``: offline Whisper speech-to-text."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from explaindrive.cli._language_common import CONFIG_HELP, console, emit_json, fail, load_config


def transcribe_command(
    file: Annotated[Path, typer.Argument(help="Audio file (WAV, FLAC or MP3).")],
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
    config: Annotated[Path | None, typer.Option("--config", help=CONFIG_HELP)] = None,
) -> None:
    """Transcribe a spoken request with Whisper (tiny.en, offline)."""
    from explaindrive.language.speech.transcriber import AudioError, Transcriber

    cfg = load_config(config)
    try:
        t = Transcriber(cfg.speech).transcribe(file)
    except (AudioError, FileNotFoundError) as exc:
        fail(str(exc))
    if as_json:
        emit_json(t.to_json())
    else:
        console.print(t.text, highlight=False)
        console.print(
            f"[dim]{t.duration_s:.2f} s of audio in {t.processing_s:.2f} s "
            f"(real-time factor {t.real_time_factor:.2f})[/]"
        )


def register(app: typer.Typer) -> None:
    """Add ``transcribe`` to the root command."""
    app.command("transcribe")(transcribe_command)
