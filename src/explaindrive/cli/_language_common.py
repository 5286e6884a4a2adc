"""Shared helpers of the language CLI commands (backend option, JSON output, errors)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, NoReturn

import typer
from rich.console import Console

from explaindrive.language.config import LanguageConfig
from explaindrive.language.encoders import check_intent_model

console = Console()
err_console = Console(stderr=True)

BACKEND_HELP = "Language backend: embedded (offline, default) or openai."
CONFIG_HELP = "YAML language config (see docs/language.md)."
INTENT_MODEL_HELP = "LLM-1 model of the embedded backend: cascade (default), minilm or mpnet."


def load_config(path: Path | None, intent_model: str | None = None) -> LanguageConfig:
    """The language config from ``path`` or the defaults, with ``intent_model`` (if given)
    replacing ``embedded.intent_model``; exits with a message on errors."""
    try:
        config = LanguageConfig() if path is None else LanguageConfig.from_yaml(path)
        if intent_model is None:
            return config
        raw = config.model_dump()
        raw["embedded"]["intent_model"] = check_intent_model(intent_model)
        return LanguageConfig.model_validate(raw)
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))


def fail(message: str, code: int = 2) -> NoReturn:
    """Print an error on stderr and exit."""
    err_console.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
    raise typer.Exit(code)


def emit_json(data: Any) -> None:
    """Print JSON on stdout, unstyled so scripts can parse it."""
    print(json.dumps(data, indent=2, ensure_ascii=False))
