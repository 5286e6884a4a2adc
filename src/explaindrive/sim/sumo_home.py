"""Locate the SUMO installation that the ``eclipse-sumo`` wheel ships.

Nothing happens at import time: callers ask for :func:`sumo_home` or
:func:`sumo_binary` when they need SUMO.
"""

from __future__ import annotations

import os
import shutil
from functools import lru_cache
from pathlib import Path


class SumoNotFoundError(RuntimeError):
    """SUMO could not be located."""


@lru_cache(maxsize=1)
def sumo_home() -> Path:
    """Return SUMO_HOME: the ``eclipse-sumo`` package first, else the environment variable.

    Also exports ``SUMO_HOME`` for child processes and SUMO's own tools.

    Raises:
        SumoNotFoundError: if neither the package nor ``$SUMO_HOME`` provides SUMO.
    """
    candidates: list[Path] = []
    try:
        import sumo  # the eclipse-sumo wheel

        candidates.append(Path(sumo.SUMO_HOME))
    except (ImportError, AttributeError):
        pass
    if os.environ.get("SUMO_HOME"):
        candidates.append(Path(os.environ["SUMO_HOME"]))
    for home in candidates:
        if (home / "bin").is_dir():
            os.environ["SUMO_HOME"] = str(home)
            return home
    raise SumoNotFoundError(
        "SUMO not found: install it with `pip install eclipse-sumo libsumo sumolib traci` "
        "or set SUMO_HOME to a SUMO installation."
    )


def sumo_binary(name: str = "sumo") -> str:
    """Path of a SUMO executable (``sumo``, ``sumo-gui``, ``netconvert``...).

    Raises:
        SumoNotFoundError: if the executable does not exist.
    """
    path = sumo_home() / "bin" / name
    if path.exists():
        return str(path)
    found = shutil.which(name)
    if found:
        return found
    raise SumoNotFoundError(f"SUMO executable {name!r} not found in {path.parent} or on PATH")
