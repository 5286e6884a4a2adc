"""Readable messages for pydantic validation errors in user files (one line, every field)."""

from __future__ import annotations

from pydantic import ValidationError


def describe_errors(exc: ValidationError, root: str = "<root>") -> str:
    """``"state.v_ego: Input should be a valid number; action: ..."`` for ``exc``.

    Args:
        exc: the validation error.
        root: the name used for an error about the whole object (empty location).
    """
    return "; ".join(
        f"{'.'.join(str(x) for x in e['loc']) or root}: {e['msg']}" for e in exc.errors()
    )
