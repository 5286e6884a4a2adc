"""SIGINT and SIGTERM in the ``explaindrive`` program: one line, the shell's exit status.

The program's entry point (:func:`explaindrive.cli.entry.main`) turns either signal into
``KeyboardInterrupt`` from the first import on, so every command stops the way it stops
on Ctrl+C, and reports the signal by name on one line, with status 128 + its number
(130 for SIGINT, 143 for SIGTERM). A command that leaves a record (``ride``) sets its own
handler with :func:`handle_signals` while it runs.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from types import FrameType

HANDLED_SIGNALS = (signal.SIGINT, signal.SIGTERM)
Handler = Callable[[int, FrameType | None], None]


class SignalInterrupt(KeyboardInterrupt):
    """The ``KeyboardInterrupt`` the program's handler raises for a signal.

    A subclass on purpose: when a plain ``KeyboardInterrupt`` passes through Python code
    that C code runs (as some extensions do while they are imported), CPython notes it and
    ends the process by SIGINT at exit, even if the exception was caught and a status
    chosen; a subclass is caught by every ``except KeyboardInterrupt`` all the same.
    """


def signal_label(signum: int) -> str:
    """``"SIGINT (Ctrl+C)"`` or ``"SIGTERM"``: a signal as the messages name it."""
    name = signal.Signals(signum).name
    return f"{name} (Ctrl+C)" if signum == signal.SIGINT else name


def exit_status(signum: int) -> int:
    """The shell's status for a command ended by ``signum`` (130 for SIGINT)."""
    return 128 + signum


@contextlib.contextmanager
def handle_signals(handler: Handler) -> Iterator[None]:
    """``handler`` takes SIGINT and SIGTERM inside the block; the previous handlers return
    after it. Outside the main thread (where handlers cannot be set) nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, handler) for sig in HANDLED_SIGNALS}
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)
