"""Shared helpers of the language CLI commands (backend option, JSON output, errors)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from rich.console import Console

from explaindrive.cli._errors import refuse

if TYPE_CHECKING:
    from explaindrive.language.config import LanguageConfig

console = Console()

BACKEND_HELP = "Language backend: embedded (offline, default) or openai."
CONFIG_HELP = "YAML language config: backend, endpoint, model, key variable, timeouts."
MODEL_HELP = "Model name for the openai backend (replaces openai.model of --config)."


def read_config(path: Path | None, model: str | None = None) -> LanguageConfig:
    """The language config from ``path`` (or the defaults) with ``model`` as the remote
    model when given.

    Raises:
        FileNotFoundError: if ``path`` does not exist.
        ValueError: if the file is malformed, or ``model`` is empty.
    """
    from explaindrive.language.config import LanguageConfig

    config = LanguageConfig() if path is None else LanguageConfig.from_yaml(path)
    return config.with_model(model)


def load_config(path: Path | None, model: str | None = None) -> LanguageConfig:
    """:func:`read_config`, exiting with one line and status 2 on errors."""
    try:
        return read_config(path, model)
    except (FileNotFoundError, ValueError) as exc:
        fail(str(exc))


def fail(message: str, code: int = 2) -> NoReturn:
    """Print an error on stderr and exit (:func:`~explaindrive.cli._errors.refuse`)."""
    refuse(message, code)


def emit_json(data: Any) -> None:
    """Print JSON on stdout, unstyled so scripts can parse it."""
    print(json.dumps(data, indent=2, ensure_ascii=False))
