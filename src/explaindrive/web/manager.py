"""One ride at a time, owned by one worker thread, watched by any number of pages.

libsumo runs one simulation per process and is not thread-safe, so every call
into the ride session (and through it into SUMO and the language lane) happens
on the manager's worker thread. Web handlers hand it typed jobs
(:mod:`explaindrive.web.jobs`) through a queue and wait on a
:class:`concurrent.futures.Future`; the worker paces the ride (one control step per
``step_period_s``) and publishes a frame after each step on the ride's board
(:mod:`explaindrive.web.board`), which the pages watch.
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
from pathlib import Path
from typing import Any

from explaindrive.redact import redact
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.web.board import Listener, RideBoard, RideState
from explaindrive.web.frames import step_frame
from explaindrive.web.jobs import (
    MAX_WAITING_UPLOADS,
    PAGE_INTERPRET_DEADLINE_S,
    RideBusyError,
    RideConflictError,
    RideJob,
    RideStartError,
)
from explaindrive.web.scene import Scene
from explaindrive.web.uploads import UploadTracker, delete_uploads_after_use

__all__ = [
    "MAX_WAITING_UPLOADS",
    "PAGE_INTERPRET_DEADLINE_S",
    "RideBusyError",
    "RideConflictError",
    "RideManager",
    "RideStartError",
    "RideState",
    "SessionFactory",
]

log = logging.getLogger(__name__)

SessionFactory = Callable[[RideConfig], RideSession]

COMMAND_TIMEOUT_S = 300.0  # [s] the first start loads the models
UPLOAD_GRACE_S = 2.0  # [s] kept past the transcription deadline before a sweep deletes it


@dataclass
class _Queued:
    job: RideJob
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
        self._jobs: queue.Queue[_Queued | None] = queue.Queue()
        self._thread: threading.Thread | None = None
        self._board = RideBoard(step_period_s)
        self._session: RideSession | None = None  # the worker's alone
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
    def submit(self, job: RideJob) -> cf.Future[Any]:
        """Queue a job for the worker.

        Raises:
            RuntimeError: if the worker is not running.
        """
        if self._thread is None or not self._thread.is_alive():
            raise RuntimeError("the ride worker is not running")
        queued = _Queued(job)
        self._jobs.put(queued)
        return queued.future

    def call(self, job: RideJob, timeout_s: float = COMMAND_TIMEOUT_S) -> Any:
        """Submit a job and wait for its answer (re-raises its error)."""
        return self.submit(job).result(timeout=timeout_s)

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
        return self._board.subscribe(listener)

    def unsubscribe(self, listener: Listener) -> None:
        """Remove a listener (no error if it is gone)."""
        self._board.unsubscribe(listener)

    def snapshot(self) -> dict[str, Any]:
        """Everything a page needs to draw the ride so far."""
        return self._board.snapshot()

    def status(self) -> dict[str, Any]:
        """The ride's state, settings and pending question."""
        return self._board.status()

    @property
    def listener_count(self) -> int:
        """Number of subscribed listeners (watching pages)."""
        return self._board.listener_count

    # ------------------------------------------------------------------ worker side
    @property
    def board(self) -> RideBoard:
        """What the pages see of the ride."""
        return self._board

    @property
    def uploads(self) -> UploadTracker:
        """The recordings waiting to be transcribed."""
        return self._uploads

    def active_session(self) -> RideSession:
        """The running or paused ride.

        Raises:
            RideConflictError: when no ride is running or paused.
        """
        state = self._board.state
        if self._session is None or state not in (RideState.RUNNING, RideState.PAUSED):
            raise RideConflictError(f"no ride is running (the ride is {state}); start one")
        return self._session

    def open_session(self, config: RideConfig) -> RideSession:
        """Build the ride's session with ``config``; its recordings are deleted once used."""
        session = self.session_factory(config)
        delete_uploads_after_use(session, self.upload_dir)
        self._uploads.max_age_s = config.audio_deadline_s + UPLOAD_GRACE_S
        self._session = session
        return session

    def end_session(self) -> None:
        """Close the current session, if any, and delete the recordings still waiting."""
        session, self._session = self._session, None
        if session is not None:
            try:
                session.close()
            except Exception:
                log.exception("error while closing the ride")
        self._uploads.clear()

    def pace_from_now(self) -> None:
        """The next control step is due now."""
        self._next_step = time.monotonic()

    def _run(self) -> None:
        """The worker: run the jobs as they come, and a control step whenever one is due."""
        while True:
            timeout = None
            if self._board.state is RideState.RUNNING:
                timeout = max(0.0, self._next_step - time.monotonic())
            try:
                queued = self._jobs.get(timeout=timeout)
            except queue.Empty:
                self._step()
                continue
            if queued is None:
                self.end_session()
                return
            try:
                queued.future.set_result(queued.job.run(self))
            except Exception as exc:
                queued.future.set_exception(exc)

    def _step(self) -> None:
        """Drive one control step and publish its frame; a failing step ends the ride."""
        session = self._session
        if session is None:
            return
        try:
            record = session.step()
            frame = step_frame(
                session, record, self._board.ride, self.scene, self._board.explained_steps
            )
        except Exception as exc:
            log.exception("the ride stopped on an error")
            self.end_session()
            self._board.fail(redact(f"{type(exc).__name__}: {exc}"))
            return
        self._uploads.sweep()
        self._next_step = max(self._next_step + self.step_period_s, time.monotonic() - 1.0)
        self._board.add_frame(frame)
        if session.done:
            self.end_session()
            self._board.set_state(RideState.FINISHED)
