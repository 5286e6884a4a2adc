"""The per-user cache: the one place that says where derived files live and how a folder
is put there whole.

Generated demand files, warm-up states and the ONNX export of the sentence encoder all live
under :func:`cache_dir`. A folder is built in a temporary
folder next to its target and :func:`publish` renames it into place with a completion
mark, so a killed run never leaves a half-written folder that looks finished.
"""

from __future__ import annotations

import os
from pathlib import Path

COMPLETE_MARK = ".complete"


def cache_dir() -> Path:
    """``$EXPLAINDRIVE_CACHE``, else ``$XDG_CACHE_HOME/explaindrive``, else
    ``~/.cache/explaindrive``."""
    own = os.environ.get("EXPLAINDRIVE_CACHE")
    if own:
        return Path(own)
    base = os.environ.get("XDG_CACHE_HOME")
    return (Path(base) if base else Path.home() / ".cache") / "explaindrive"


def is_complete(folder: Path) -> bool:
    """Whether ``folder`` was put in place by :func:`publish`."""
    return (folder / COMPLETE_MARK).is_file()


def publish(staged: Path, target: Path, note: str = "ok\n") -> Path:
    """Mark the finished folder ``staged`` complete (with ``note``) and rename it to
    ``target``; if another process published ``target`` first, keep theirs.

    ``staged`` must lie next to ``target`` (same file system), normally inside a temporary
    folder that is removed afterwards.

    Raises:
        OSError: if the rename fails and ``target`` is not complete.
    """
    (staged / COMPLETE_MARK).write_text(note, encoding="utf-8")
    try:
        staged.rename(target)
    except OSError:
        if not is_complete(target):
            raise
    return target
