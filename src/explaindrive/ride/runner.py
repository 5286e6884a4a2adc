"""Run a ride to its end: script lines in, ``events.jsonl``/``summary.json``/``ride.png`` out."""

from __future__ import annotations

import json
import logging
import queue
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from explaindrive.jsonsafe import finite
from explaindrive.language.intent import parse_confirmation_answer
from explaindrive.ride.plot import plot_ride
from explaindrive.ride.script import AUDIO_PREFIX, ScriptLine
from explaindrive.ride.session import RideSession, StepRecord

log = logging.getLogger(__name__)

WRITE_LAG_STEPS = 3  # records are written once late language results can no longer change them


@dataclass(frozen=True)
class RideOutputs:
    """Files a ride wrote."""

    events: Path
    summary: Path
    figure: Path


def _json_default(value: Any) -> Any:
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON serialisable: {value!r}")


def _write(fh: IO[str], rec: StepRecord) -> None:
    fh.write(json.dumps(finite(rec.to_json()), default=_json_default) + "\n")
    fh.flush()


def run_ride(
    session: RideSession,
    lines: Sequence[ScriptLine],
    out_dir: Path,
    *,
    typed: queue.Queue[str] | None = None,
    on_step: Callable[[StepRecord], None] | None = None,
) -> RideOutputs:
    """Drive ``session`` to the end of the ride.

    Args:
        session: a fresh ride session (started here).
        lines: timed passenger lines (already validated).
        out_dir: where ``events.jsonl``, ``summary.json`` and ``ride.png`` go.
        typed: lines typed by the passenger while the ride runs (interactive mode);
            "yes"/"no" answers a pending confirmation question.
        on_step: called after every step (live view).
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    outputs = RideOutputs(out_dir / "events.jsonl", out_dir / "summary.json", out_dir / "ride.png")
    todo = deque(lines)
    held: list[str] = []  # typed answers waiting for their question
    written = 0
    session.start()
    try:
        with outputs.events.open("w", encoding="utf-8") as fh:
            while not session.done:
                tick = time.monotonic()
                while todo and todo[0].t <= session.t:
                    line = todo.popleft()
                    if line.audio is not None:
                        session.say_audio(line.audio, confirm=line.confirm)
                    else:
                        session.say(line.say or "", confirm=line.confirm)
                _drain_typed(session, typed, held)
                rec = session.step()
                if on_step is not None:
                    on_step(rec)
                while written < len(session.records) - WRITE_LAG_STEPS:
                    _write(fh, session.records[written])
                    written += 1
                if session.config.realtime:
                    time.sleep(max(0.0, 1.0 - (time.monotonic() - tick)))
            for rec in session.records[written:]:
                _write(fh, rec)
    finally:
        session.close()
    summary = session.summary()
    summary["unused_script_lines"] = [line.model_dump(mode="json") for line in todo]
    outputs.summary.write_text(json.dumps(finite(summary), indent=2, default=_json_default))
    plot_ride(
        session.records,
        outputs.figure,
        title=f"Ride: traffic {session.config.traffic_level:g}, seed {session.config.seed}",
    )
    return outputs


def _drain_typed(
    session: RideSession, typed: queue.Queue[str] | None, held: list[str] | None = None
) -> None:
    """Hand typed lines to the session; a yes/no typed while a request is still being
    interpreted waits (in ``held``) for its question instead of becoming a new request."""
    if typed is None:
        return
    lines = list(held or [])
    if held is not None:
        held.clear()
    while True:
        try:
            lines.append(typed.get_nowait())
        except queue.Empty:
            break
    for raw in lines:
        text = raw.strip()
        if not text:
            continue
        if text.startswith(AUDIO_PREFIX):
            session.say_audio(Path(text[len(AUDIO_PREFIX) :]))
            continue
        answer = parse_confirmation_answer(text)
        if answer is not None and session.pending_confirmation is not None:
            session.answer(answer)
        elif answer is not None and session.interpreting and held is not None:
            held.append(raw)
        else:
            session.say(text)
