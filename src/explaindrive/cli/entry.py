"""The ``explaindrive`` program: signals are handled before the first heavy import.

Imports of the command modules take a second or more (torch, matplotlib); a Ctrl+C or a
SIGTERM in that time, or in a command without its own handling, ends the program with one
line naming the signal and status 128 + its number, never a traceback. Later signals,
while the program is already stopping, are noted and do nothing.
"""

from __future__ import annotations

import sys
from types import FrameType

from explaindrive.cli._signals import HANDLED_SIGNALS, exit_status, signal_label


def main() -> None:
    """Run the command line (the ``explaindrive`` script and ``python -m explaindrive.cli``)."""
    import signal

    received: list[int] = []

    def stop(signum: int, frame: FrameType | None) -> None:
        received.append(signum)
        if len(received) == 1:
            raise KeyboardInterrupt

    for sig in HANDLED_SIGNALS:
        signal.signal(sig, stop)
    code: int | str | None = 0
    try:
        from explaindrive.cli.main import app

        app()
    except KeyboardInterrupt:
        code = exit_status(received[0] if received else signal.SIGINT)
    except SystemExit as exc:
        code = exc.code
    if received:  # this handler took the signal: no command reported it
        print(f"error: stopped by {signal_label(received[0])}", file=sys.stderr)
        code = exit_status(received[0])
    sys.exit(code)
