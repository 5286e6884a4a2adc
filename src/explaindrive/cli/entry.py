"""The ``explaindrive`` program: one line for every refusal, signals handled from the start.

A usage error (an unknown option, a number outside its range, a missing argument) is one
line, ``error: <what is wrong>``, with exit status 2. A command that needs an extra that is
not installed says which, on one line, with exit status 1. Imports of the command modules take
a second or more (torch, matplotlib); a Ctrl+C or a SIGTERM in that time, or in a command
without its own handling, ends the program with one line naming the signal and status
128 + its number, never a traceback. Later signals, while the program is already
stopping, are noted and do nothing. After a signal (taken here or by the command, which
then ends with 128 + its number) the program leaves once its own clean-up (every
``finally`` on the way out) has run, without the interpreter's
finalization: an extension interrupted while it was being imported can leave a native
thread behind that aborts the finalization ("PyThreadState_Get: the function must be
called with the GIL held"), which would turn status 130 into a crash.
"""

from __future__ import annotations

import os
import sys
from types import FrameType

from explaindrive.cli._signals import HANDLED_SIGNALS, SignalInterrupt, exit_status, signal_label


def command_name(args: list[str]) -> str:
    """``explaindrive <command>`` for the command line ``args``, for error messages."""
    words = [a for a in args if not a.startswith("-")][:1]
    return " ".join(["explaindrive", *words])


def main() -> None:
    """Run the command line (the ``explaindrive`` script and ``python -m explaindrive.cli``)."""
    import signal

    received: list[int] = []

    def stop(signum: int, frame: FrameType | None) -> None:
        received.append(signum)
        if len(received) == 1:
            raise SignalInterrupt

    for sig in HANDLED_SIGNALS:
        signal.signal(sig, stop)
    code: int | str | None = 0
    try:
        from typer import Abort
        from typer._click.exceptions import ClickException, NoArgsIsHelpError

        from explaindrive.cli.app import app

        try:
            result = app(standalone_mode=False)  # errors are reported here, on one line
            code = result if isinstance(result, int) else 0
        except NoArgsIsHelpError as exc:
            exc.show()
            code = exc.exit_code
        except ClickException as exc:
            print(f"error: {exc.format_message()}", file=sys.stderr)
            code = exc.exit_code
        except Abort:
            print("error: aborted", file=sys.stderr)
            code = 1
        except ModuleNotFoundError as exc:  # a package of an extra that is not installed
            from explaindrive.extras import missing_extra

            missing = missing_extra(exc, command_name(sys.argv[1:]))
            if missing is None:
                raise
            print(f"error: {missing}", file=sys.stderr)
            code = 1
    except KeyboardInterrupt:
        code = exit_status(received[0] if received else signal.SIGINT)
    except SystemExit as exc:
        code = exc.code
    if received:  # this handler took the signal: no command reported it
        print(f"error: stopped by {signal_label(received[0])}", file=sys.stderr)
        code = exit_status(received[0])
    if code in {exit_status(sig) for sig in HANDLED_SIGNALS}:  # stopped by a signal
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(int(code))  # no finalization (module docstring)
    sys.exit(code)
