"""Passenger commands: the one place that names them and fixes their codes.

The paper abstracts every passenger request into three commands and feeds the
command code to the driving policy as the first state component (``cmd``).
"""

from __future__ import annotations

from enum import IntEnum


class Command(IntEnum):
    """A passenger command; the integer value is the ``cmd`` state component."""

    FAST = 0
    COMFORT = 1
    STOP = 2

    @property
    def label(self) -> str:
        """Lower-case name used in configs, files and the CLI (``fast``...)."""
        return _LABELS[self]

    @classmethod
    def parse(cls, value: str | int | Command) -> Command:
        """Parse a command from its name (any case) or its integer code.

        Raises:
            ValueError: if ``value`` names no command.
        """
        if isinstance(value, Command):
            return value
        if isinstance(value, int) and not isinstance(value, bool):
            try:
                return cls(value)
            except ValueError:
                pass
        elif isinstance(value, str):
            key = value.strip().upper()
            if key in cls.__members__:
                return cls[key]
        names = ", ".join(c.label for c in cls)
        raise ValueError(f"unknown command {value!r}; expected one of: {names} (or 0, 1, 2)")


_LABELS = {c: c.name.lower() for c in Command}
COMMAND_LABELS: tuple[str, ...] = tuple(c.label for c in Command)
