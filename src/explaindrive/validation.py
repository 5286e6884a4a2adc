"""Readable messages for pydantic validation errors in user files (one line, every field)."""

from __future__ import annotations

from pydantic import ValidationError
from pydantic_core import ErrorDetails

_MAX_SHOWN_CHARS = 60  # longer inputs are not repeated in a message


def describe_errors(exc: ValidationError, root: str = "<root>") -> str:
    """``"state.v_ego: Input should be a valid number, got 'fast'; action: ..."`` for ``exc``.

    Args:
        exc: the validation error.
        root: the name used for an error about the whole object (empty location).
    """
    return "; ".join(describe_error(e, root) for e in exc.errors())


def describe_error(error: ErrorDetails, root: str = "<root>") -> str:
    """One error as ``"location: message"``.

    The message of a ``ValueError`` raised by a validator is used as it is; pydantic's own
    messages get the offending input appended when it is a short scalar.

    Args:
        error: one item of :meth:`pydantic.ValidationError.errors`.
        root: the name used for an error about the whole object; with ``""`` such an
            error is the message alone.
    """
    if error["type"] == "value_error":
        message = str(error.get("ctx", {}).get("error", error["msg"]))
    else:
        message = error["msg"]
        value = error.get("input")
        shown = repr(value)
        if (
            error["type"] not in ("missing", "extra_forbidden")
            and (value is None or isinstance(value, int | float | str))
            and len(shown) <= _MAX_SHOWN_CHARS
        ):
            message += f", got {shown}"
    where = ".".join(str(x) for x in error["loc"]) or root
    return f"{where}: {message}" if where else message
