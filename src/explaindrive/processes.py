"""Worker processes and Ctrl+C: the parent alone decides how a run stops.

A terminal sends Ctrl+C's SIGINT to its whole process group, worker processes included.
A ``spawn`` worker that gets it while it imports torch prints a ``KeyboardInterrupt``
traceback of its own, whatever the parent does. Processes started inside
:func:`children_ignore_sigint` ignore SIGINT from their first instruction on (an ignored
signal stays ignored across ``exec``, and Python then leaves it so); the parent stops
them, and a worker that wants SIGINT back once it is ready calls
:func:`restore_sigint`.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator


@contextlib.contextmanager
def children_ignore_sigint() -> Iterator[None]:
    """Processes started in the block begin with SIGINT ignored; this process ignores it
    in the block too (starting them takes milliseconds). Outside the main thread, where
    handlers cannot be set, nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def restore_sigint() -> None:
    """In a worker started by :func:`children_ignore_sigint`: SIGINT raises
    ``KeyboardInterrupt`` again (Python's default)."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
