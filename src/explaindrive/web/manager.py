"""One ride at a time, owned by one worker thread, watched by any number of pages.

libsumo runs one simulation per process and is not thread-safe, so every call
into the ride session (and through it into SUMO and the language lane) happens
on the manager's worker thread. Web handlers hand it commands through a queue
and wait on a :class:`concurrent.futures.Future`; the worker paces the ride
(one control step per ``step_period_s``) and publishes a frame after each step
to the subscribed listeners.
"""

from __future__ import annotations

import concurrent.futures as cf
import logging
import queue
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import Any

from explaindrive.commands import Command
from explaindrive.jsonsafe import finite
from explaindrive.redact import redact, redact_json
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession, StepRecord
from explaindrive.web.models import StartRequest
from explaindrive.web.scene import Scene, snapshot
from explaindrive.web.uploads import UploadTracker, delete_uploads_after_use

log = logging.getLogger(__name__)

SessionFactory = Callable[[RideConfig], RideSession]
Listener = Callable[[dict[str, Any]], None]

LOG_LIMIT = 200  # passenger events kept for pages that join late
EXPLANATION_SCAN_STEPS = 30  # explanations attach to earlier steps; look this far back
COMMAND_TIMEOUT_S = 300.0  # [s] the first start loads the models
MAX_WAITING_UPLOADS = 4  # recordings stored and not yet transcribed
UPLOAD_GRACE_S = 2.0  # [s] kept past the transcription deadline before a sweep deletes it
PAGE_INTERPRET_DEADLINE_S = RideConfig().audio_deadline_s
"""[s] The typed-request deadline of a ride on the page. That ride is paced and never waits
on language, so a typed request is given as long as a spoken one
(:attr:`RideConfig.audio_deadline_s`); a terminal ride fast-forwards and pauses for a typed
request at most :attr:`RideConfig.interpret_deadline_s`."""


class RideState(StrEnum):
    """Where the ride is."""

    IDLE = "idle"
    STARTING = "starting"
    RUNNING = "running"
    PAUSED = "paused"
    FINISHED = "finished"
    FAILED = "failed"


class RideConflictError(RuntimeError):
    """The request does not fit the ride's current state (HTTP 409)."""


class RideStartError(RuntimeError):
    """The ride could not be started (models, policies or SUMO; HTTP 503)."""


class RideBusyError(RuntimeError):
    """Too many recordings are waiting to be transcribed (HTTP 429)."""


@dataclass
class _Job:
    name: str
    args: tuple[Any, ...]
    future: cf.Future[Any] = field(default_factory=cf.Future)


class RideManager:
    """Owns the current ride and its worker thread.

    Args:
        session_factory: builds a ride session from its settings (called on the worker).
        scene: the static road scene (signal heads are looked up each step).
        step_period_s: wall time between control steps [s]; 1.0 is real time.
        upload_dir: where uploaded audio is kept until it is transcribed (a fresh temporary
            directory when omitted).
    """

    def __init__(
        self,
        session_factory: SessionFactory,
        scene: Scene,
        *,
        step_period_s: float = 1.0,
        upload_dir: Path | None = None,
    ) -> None:
        if not step_period_s > 0:
            raise ValueError(f"step_period_s must be > 0, got {step_period_s}")
        self.session_factory = session_factory
        self.scene = scene
        self.step_period_s = step_period_s
        self._tmp = None if upload_dir else tempfile.TemporaryDirectory(prefix="explaindrive-web-")
        self.upload_dir = upload_dir or Path(self._tmp.name)  # type: ignore[union-attr]
        self._jobs: queue.Queue[_Job | None] = queue.Queue()
        self._lock = threading.Lock()
        self._listeners: list[Listener] = []
        self._thread: threading.Thread | None = None
        # ride state, written by the worker, read under the lock
        self._session: RideSession | None = None
        self._state = RideState.IDLE
        self._ride = 0
        self._settings: StartRequest | None = None
        self._error: str | None = None
        self._history: list[dict[str, Any]] = []
        self._explanations: list[dict[str, Any]] = []
        self._log: list[dict[str, Any]] = []
        self._last_frame: dict[str, Any] | None = None
        self._question: str | None = None
        self._explained_steps: set[int] = set()
        self._uploads = UploadTracker(RideConfig().audio_deadline_s + UPLOAD_GRACE_S)
        self._next_step = 0.0

    # ------------------------------------------------------------------ lifecycle
    def start_worker(self) -> None:
        """Start the worker thread (idempotent)."""
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="ride-worker", daemon=True)
            self._thread.start()

    def shutdown(self, timeout_s: float = 10.0) -> None:
        """End the ride, stop the worker and delete uploaded audio."""
        if self._thread is not None:
            self._jobs.put(None)
            self._thread.join(timeout_s)
            self._thread = None
        if self._tmp is not None:
            self._tmp.cleanup()

    # ------------------------------------------------------------------ web side
    def submit(self, name: str, *args: Any) -> cf.Future[Any]:
        """Queue a command for the worker: start, pause, resume, reset, say, audio, answer.

        Raises:
            RuntimeError: if the worker is not running.
        """
        if self._thread is None or not self._thread.is_alive():
            raise RuntimeError("the ride worker is not running")
        job = _Job(name, args)
        self._jobs.put(job)
        return job.future

    def call(self, name: str, *args: Any, timeout_s: float = COMMAND_TIMEOUT_S) -> Any:
        """Submit a command and wait for its result (re-raises its error)."""
        return self.submit(name, *args).result(timeout=timeout_s)

    def new_upload_path(self, suffix: str) -> Path:
        """A fresh file in the upload directory; its name is chosen here, never by a client."""
        handle = tempfile.NamedTemporaryFile(  # noqa: SIM115 - the file outlives this call
            dir=self.upload_dir, prefix="utterance-", suffix=suffix, delete=False
        )
        handle.close()
        return Path(handle.name)

    def subscribe(self, listener: Listener) -> dict[str, Any]:
        """Add a listener for published messages; returns the snapshot it starts from.

        The listener is called on the worker thread and must return at once.
        """
        with self._lock:
            self._listeners.append(listener)
            return self._snapshot_locked()

    def unsubscribe(self, listener: Listener) -> None:
        """Remove a listener (no error if it is gone)."""
        with self._lock:
            if listener in self._listeners:
                self._listeners.remove(listener)

    def snapshot(self) -> dict[str, Any]:
        """Everything a page needs to draw the ride so far."""
        with self._lock:
            return self._snapshot_locked()

    def status(self) -> dict[str, Any]:
        """The ride's state, settings and pending question."""
        with self._lock:
            return self._status_locked()

    @property
    def listener_count(self) -> int:
        """Number of subscribed listeners (watching pages)."""
        with self._lock:
            return len(self._listeners)

    # ------------------------------------------------------------------ worker
    def _run(self) -> None:
        while True:
            timeout = None
            if self._state is RideState.RUNNING:
                timeout = max(0.0, self._next_step - time.monotonic())
            try:
                job = self._jobs.get(timeout=timeout)
            except queue.Empty:
                job = _Job("step", ())
            if job is None:
                self._end_session()
                return
            if job.name == "step":
                self._step()
                continue
            try:
                job.future.set_result(getattr(self, f"_do_{job.name}")(*job.args))
            except Exception as exc:
                job.future.set_exception(exc)

    def _do_start(self, settings: StartRequest) -> dict[str, Any]:
        if self._state in (RideState.RUNNING, RideState.PAUSED, RideState.STARTING):
            raise RideConflictError(f"a ride is already {self._state.value}; reset it first")
        self._end_session()
        config = RideConfig(
            traffic_level=settings.traffic_level,
            seed=settings.seed,
            max_steps=settings.max_steps,
            realtime=True,
            interpret_deadline_s=PAGE_INTERPRET_DEADLINE_S,
        )
        with self._lock:
            self._ride += 1
            self._settings = settings
            self._state = RideState.STARTING
            self._error = None
            self._history, self._explanations, self._log = [], [], []
            self._last_frame, self._question = None, None
            self._explained_steps = set()
        self._publish({"type": "status", **self.status()})
        try:
            session = self.session_factory(config)
            delete_uploads_after_use(session, self.upload_dir)
            self._uploads.max_age_s = config.audio_deadline_s + UPLOAD_GRACE_S
            self._session = session
            session.start(Command.parse(settings.command))
        except Exception as exc:
            log.error("the ride could not start: %s", exc)
            log.debug("start failure", exc_info=True)
            self._end_session()
            with self._lock:
                self._state = RideState.FAILED
                self._error = redact(f"{type(exc).__name__}: {exc}")
            self._publish({"type": "status", **self.status()})
            raise RideStartError(redact(f"the ride could not start: {exc}")) from exc
        self._next_step = time.monotonic()
        self._set_state(RideState.RUNNING)
        return self.status()

    def _do_pause(self) -> dict[str, Any]:
        if self._state is not RideState.RUNNING:
            raise RideConflictError(
                f"only a running ride can be paused (the ride is {self._state})"
            )
        self._set_state(RideState.PAUSED)
        return self.status()

    def _do_resume(self) -> dict[str, Any]:
        if self._state is not RideState.PAUSED:
            raise RideConflictError(f"only a paused ride can resume (the ride is {self._state})")
        self._next_step = time.monotonic()
        self._set_state(RideState.RUNNING)
        return self.status()

    def _do_reset(self) -> dict[str, Any]:
        self._end_session()
        with self._lock:
            self._settings, self._error = None, None
            self._history, self._explanations, self._log = [], [], []
            self._last_frame, self._question = None, None
        self._set_state(RideState.IDLE)
        return self.status()

    def _active_session(self) -> RideSession:
        if self._session is None or self._state not in (RideState.RUNNING, RideState.PAUSED):
            raise RideConflictError(f"no ride is running (the ride is {self._state}); start one")
        return self._session

    def _do_say(self, text: str) -> dict[str, Any]:
        return {"id": self._active_session().say(text)}

    def _do_audio(self, path: Path) -> dict[str, Any]:
        session = self._active_session()
        if self._uploads.waiting() >= MAX_WAITING_UPLOADS:
            raise RideBusyError(
                f"{MAX_WAITING_UPLOADS} recordings are still being transcribed; try again soon"
            )
        self._uploads.add(path)
        return {"id": session.say_audio(path)}

    def _do_answer(self, yes: bool) -> dict[str, Any]:
        session = self._active_session()
        pending = session.pending_confirmation
        if pending is None:
            raise RideConflictError("no confirmation question is pending")
        session.answer(yes)
        with self._lock:
            self._question = None
        self._publish({"type": "status", **self.status()})
        return {"id": pending.id, "answer": "yes" if yes else "no"}

    def _step(self) -> None:
        session = self._session
        if session is None:
            return
        try:
            record = session.step()
            frame = self._frame(session, record)
        except Exception as exc:
            log.exception("the ride stopped on an error")
            self._end_session()
            with self._lock:
                self._state = RideState.FAILED
                self._error = redact(f"{type(exc).__name__}: {exc}")
            self._publish({"type": "status", **self.status()})
            return
        self._uploads.sweep()
        self._next_step = max(self._next_step + self.step_period_s, time.monotonic() - 1.0)
        with self._lock:
            self._history.append(
                {
                    "t": frame["t"],
                    "speed_mps": frame["speed_mps"],
                    "limit_mps": frame["limit_mps"],
                    "command": frame["command"],
                }
            )
            self._explanations.extend(frame["explanations"])
            self._log = (self._log + frame["passenger"])[-LOG_LIMIT:]
            self._last_frame = frame
            self._question = frame["question"]
        self._publish(frame)
        if session.done:
            self._end_session()
            self._set_state(RideState.FINISHED)

    def _frame(self, session: RideSession, record: StepRecord) -> dict[str, Any]:
        explanations = []
        first = max(0, len(session.records) - EXPLANATION_SCAN_STEPS)
        for index in range(first, len(session.records)):
            exp = session.records[index].explanation
            if exp is not None and index not in self._explained_steps:
                self._explained_steps.add(index)
                explanations.append(
                    {
                        "t": session.records[index].t,
                        "text": redact(exp["text"]),
                        "factor": exp["factor"],
                    }
                )
        pending = session.pending_confirmation
        return finite(
            {
                "type": "frame",
                "ride": self._ride,
                "t": record.t,
                "command": record.command,
                "agent": record.agent,
                "action": record.action,
                "speed_mps": round(record.speed_mps, 3),
                "limit_mps": round(record.limit_mps, 3),
                "state": record.state,
                "flags": record.flags,
                "passenger": redact_json([_public_event(e) for e in record.passenger]),
                "question": _redacted(pending.question) if pending is not None else None,
                "explanations": explanations,
                "scene": snapshot(session.env.sumo, self.scene),
            }
        )

    def _end_session(self) -> None:
        session, self._session = self._session, None
        if session is not None:
            try:
                session.close()
            except Exception:
                log.exception("error while closing the ride")
        self._uploads.clear()

    def _set_state(self, state: RideState) -> None:
        with self._lock:
            self._state = state
        self._publish({"type": "status", **self.status()})

    def _publish(self, message: dict[str, Any]) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for listener in listeners:
            try:
                listener(message)
            except Exception:
                log.exception("a listener failed; removing it")
                self.unsubscribe(listener)

    # ------------------------------------------------------------------ snapshots
    def _status_locked(self) -> dict[str, Any]:
        settings = self._settings.model_dump() if self._settings is not None else None
        return {
            "state": self._state.value,
            "ride": self._ride,
            "settings": settings,
            "error": self._error,
            "t": self._last_frame["t"] if self._last_frame else 0.0,
            "question": self._question,
            "step_period_s": self.step_period_s,
        }

    def _snapshot_locked(self) -> dict[str, Any]:
        return {
            "type": "snapshot",
            "status": self._status_locked(),
            "history": list(self._history),
            "explanations": list(self._explanations),
            "log": list(self._log),
            "frame": self._last_frame,
        }


def _redacted(text: str | None) -> str | None:
    """``text`` with secrets masked (``None`` stays ``None``)."""
    return redact(text) if text is not None else None


def _public_event(event: dict[str, Any]) -> dict[str, Any]:
    """A passenger event without server file paths or a remote model's raw reply."""
    event = {k: v for k, v in event.items() if k != "raw_reply"}
    if event.get("audio"):
        return {**event, "audio": "uploaded recording"}
    return event
