"""Run a ride to its end: script lines in, ``events.jsonl``/``summary.json``/``ride.png`` out.

A ride never costs the record of an earlier one: :func:`prepare_out_dir` checks the output
folder (refused if it holds anything, unless told to replace a previous ride) and makes a
fresh staging folder next to it, ``.<name>.new``; the ride writes there, and
:func:`commit_ride` moves its files into the output folder only once they are complete
(the summary last). A ride stopped before its first step is dropped with
:func:`discard_ride`, leaving the folder as it was. Steps are appended to ``events.jsonl``
as soon as late language results can no longer change them, and the figure and the
summary are written last, each under a temporary name first. A ride that is stopped
(a signal, see ``stop``) or fails still writes every step it drove, then its figure and
its summary, marked ``interrupted`` with the reason and the signal's name.
"""

from __future__ import annotations

import json
import logging
import os
import queue
import shutil
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from explaindrive.jsonsafe import finite
from explaindrive.redact import redact, redact_json
from explaindrive.ride.inputs import PassengerInput, TypedLine
from explaindrive.ride.plot import plot_ride
from explaindrive.ride.records import StepRecord
from explaindrive.ride.script import ScriptLine
from explaindrive.ride.session import RideSession

log = logging.getLogger(__name__)

WRITE_LAG_STEPS = 3  # records are written once late language results can no longer change them
EVENTS_NAME, SUMMARY_NAME, FIGURE_NAME = "events.jsonl", "summary.json", "ride.png"


def stop_reason(signum: int) -> str:
    """``"stopped by SIGINT (Ctrl+C)"``: how a ride ended by the signal ``signum`` is marked."""
    name = signal.Signals(signum).name
    return f"stopped by {name}" + (" (Ctrl+C)" if signum == signal.SIGINT else "")


STOPPED = stop_reason(signal.SIGINT)  # Ctrl+C, or a stop without a reason


class StopRequest(threading.Event):
    """A ride's stop flag that keeps the signal that set it (the first one counts)."""

    def __init__(self) -> None:
        super().__init__()
        self.signum: int = signal.SIGINT

    def request(self, signum: int) -> None:
        """Stop the ride after the current step, because of ``signum``."""
        if not self.is_set():
            self.signum = signum
            self.set()


class OutputDirError(ValueError):
    """The output folder cannot take a new ride."""


@dataclass(frozen=True)
class RideOutputs:
    """Files a ride wrote, why it ended early (``None``: it ran to its end) and the signal
    that ended it, if one did."""

    events: Path
    summary: Path
    figure: Path
    interrupted: str | None = None
    signum: int | None = None


def output_files(out_dir: Path) -> RideOutputs:
    """Where a ride in ``out_dir`` writes its files."""
    return RideOutputs(out_dir / EVENTS_NAME, out_dir / SUMMARY_NAME, out_dir / FIGURE_NAME)


def staging_dir(out_dir: Path) -> Path:
    """The folder a ride for ``out_dir`` is written into first: ``.<name>.new`` beside it."""
    return out_dir.parent / f".{out_dir.name}.new"


def prepare_out_dir(out_dir: Path, force: bool = False) -> Path:
    """Check that ``out_dir`` can take a new ride; returns the staging folder to write it into.

    Nothing is created and nothing in ``out_dir`` is touched: :func:`run_ride` makes the
    staging folder, and :func:`commit_ride` replaces a previous ride's files once the new
    ride has a record of its own. A staging folder left by a ride that was killed outright
    (SIGKILL) is removed.

    Args:
        out_dir: the ride's output folder (need not exist).
        force: accept a folder that already holds files (a previous ride's are replaced
            at the end; anything else is kept) instead of refusing.

    Returns:
        The staging folder (:func:`staging_dir`).

    Raises:
        OutputDirError: if ``out_dir`` is a file, holds files and ``force`` is off, or
            cannot be made (a file on the way, no permission).
    """
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputDirError(f"--out {out_dir} is a file, not a folder; name a folder")
    entries = sorted(p.name for p in out_dir.iterdir()) if out_dir.is_dir() else []
    if entries and not force:
        shown = ", ".join(entries[:3]) + (", ..." if len(entries) > 3 else "")
        raise OutputDirError(
            f"--out {out_dir} is not empty ({shown}); choose a new folder, or add --force "
            "to replace the ride in it"
        )
    parent = next(p for p in out_dir.parents if p.exists())  # "." or "/" at the latest
    if not parent.is_dir():
        raise OutputDirError(f"--out {out_dir}: {parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputDirError(f"--out {out_dir} cannot be made in {parent} (permission denied)")
    staging = staging_dir(out_dir)
    shutil.rmtree(staging, ignore_errors=True)
    return staging


def commit_ride(staging: Path, out_dir: Path) -> RideOutputs:
    """Move a finished (or interrupted) ride's files from ``staging`` into ``out_dir``,
    replacing a previous ride's; the summary goes last, so a summary in ``out_dir`` always
    belongs to the events beside it once the move is over. ``staging`` is removed."""
    out_dir.mkdir(parents=True, exist_ok=True)
    new, final = output_files(staging), output_files(out_dir)
    for src, dst in ((new.events, final.events), (new.figure, final.figure),
                     (new.summary, final.summary)):  # fmt: skip
        os.replace(src, dst)
    discard_ride(staging)
    return final


def discard_ride(staging: Path) -> None:
    """Remove a staging folder and whatever a ride left in it."""
    shutil.rmtree(staging, ignore_errors=True)


def _json_default(value: Any) -> Any:
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON serialisable: {value!r}")


def _write(fh: IO[str], rec: StepRecord) -> None:
    line = redact_json(finite(rec.to_json()))
    fh.write(json.dumps(line, default=_json_default) + "\n")
    fh.flush()


class _EventLog:
    """``events.jsonl``, written step by step, ``WRITE_LAG_STEPS`` behind the ride."""

    def __init__(self, fh: IO[str]) -> None:
        self.fh = fh
        self.written = 0

    def catch_up(self, records: Sequence[StepRecord], lag: int = WRITE_LAG_STEPS) -> None:
        """Write every record but the last ``lag`` ones."""
        while self.written < len(records) - lag:
            _write(self.fh, records[self.written])
            self.written += 1


def run_ride(
    session: RideSession,
    lines: Sequence[ScriptLine],
    out_dir: Path,
    *,
    typed: queue.Queue[PassengerInput | str] | None = None,
    on_step: Callable[[StepRecord], None] | None = None,
    stop: threading.Event | None = None,
) -> RideOutputs:
    """Drive ``session`` to the end of the ride (or until ``stop`` is set).

    Args:
        session: a fresh ride session (started here).
        lines: timed passenger lines (already validated).
        out_dir: where ``events.jsonl``, ``summary.json`` and ``ride.png`` go (the CLI
            passes the staging folder of :func:`prepare_out_dir`; created here if missing).
        typed: lines the passenger types or speaks while the ride runs (interactive
            mode; a ``str`` is typed text); a typed "yes"/"no" answers a pending
            confirmation question.
        on_step: called after every step (live view).
        stop: when set, the ride ends after the current step and is marked interrupted
            (with the signal of a :class:`StopRequest`, else as by Ctrl+C).

    Returns:
        The files written; ``interrupted`` says why the ride ended early (``stop`` set,
        or a ``KeyboardInterrupt``, which ends the ride as Ctrl+C does).

    Raises:
        Exception: whatever error stopped the ride, once the outputs are written.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    outputs = output_files(out_dir)
    todo = deque(lines)
    failure: Exception | None = None
    reason: str | None = None
    signum: int | None = None
    try:
        session.start()
        with outputs.events.open("w", encoding="utf-8") as fh:
            events = _EventLog(fh)
            try:
                _drive(session, todo, events, typed, on_step, stop)
                signum = stop.signum if isinstance(stop, StopRequest) else signal.SIGINT
                reason = None if session.done else stop_reason(signum)
            except KeyboardInterrupt:
                signum, reason = signal.SIGINT, STOPPED
            except Exception as exc:
                failure, signum = exc, None
                reason = redact(f"stopped on an error: {type(exc).__name__}: {exc}")
            finally:
                events.catch_up(session.records, lag=0)
    finally:
        session.close()
    signum = signum if reason else None
    _finish(session, todo, outputs, events.written, reason, signum)
    if failure is not None:
        raise failure
    return RideOutputs(outputs.events, outputs.summary, outputs.figure, reason, signum)


def _drive(
    session: RideSession,
    todo: deque[ScriptLine],
    events: _EventLog,
    typed: queue.Queue[PassengerInput | str] | None,
    on_step: Callable[[StepRecord], None] | None,
    stop: threading.Event | None,
) -> None:
    """The ride loop: due lines, typed input, one step, the event log, the pace."""
    while not session.done and not (stop is not None and stop.is_set()):
        tick = time.monotonic()
        while todo and todo[0].t <= session.t:
            line = todo.popleft()
            session.hear(line.line, confirm=line.answer)
        _drain_typed(session, typed)
        rec = session.step()
        if on_step is not None:
            on_step(rec)
        events.catch_up(session.records)
        if session.config.realtime:
            pause_s = max(0.0, 1.0 - (time.monotonic() - tick))
            if stop is not None:
                stop.wait(pause_s)
            else:
                time.sleep(pause_s)


def _finish(
    session: RideSession,
    todo: deque[ScriptLine],
    outputs: RideOutputs,
    steps: int,
    reason: str | None,
    signum: int | None,
) -> None:
    """Write the figure, then the summary (each under a temporary name first)."""
    summary = session.summary()
    summary["steps"] = steps
    summary["interrupted"] = reason is not None
    summary["interruption"] = reason
    summary["signal"] = None if signum is None else signal.Signals(signum).name
    summary["unused_script_lines"] = [line.model_dump(mode="json") for line in todo]
    title = f"Ride: traffic {session.config.traffic_level:g}, seed {session.config.seed}"
    if reason is not None:
        title += f" (interrupted after {steps} s)"
    figure_tmp = outputs.figure.with_name(f".{outputs.figure.stem}.tmp.png")
    plot_ride(session.records[:steps], figure_tmp, title=title)
    os.replace(figure_tmp, outputs.figure)
    summary_tmp = outputs.summary.with_name(f".{outputs.summary.name}.tmp")
    text = json.dumps(redact_json(finite(summary)), indent=2, default=_json_default)
    summary_tmp.write_text(text, encoding="utf-8")
    os.replace(summary_tmp, outputs.summary)


def _drain_typed(session: RideSession, typed: queue.Queue[PassengerInput | str] | None) -> None:
    """Hand the passenger's lines to the session: requests, and yes/no answers, which LLM-1
    reads as such (:meth:`~explaindrive.ride.requests.PassengerRequests.on_interpretation`)."""
    if typed is None:
        return
    while True:
        try:
            item = typed.get_nowait()
        except queue.Empty:
            break
        line = TypedLine(item) if isinstance(item, str) else item
        if isinstance(line, TypedLine) and not line.text.strip():
            continue
        session.hear(line)
