"""The commands a page sends the ride, one typed job each, run on the ride worker.

Each job is a small class whose :meth:`RideJob.run` does its one piece of work through
the worker's side of the manager (:class:`RideWorker`) and returns the JSON answer; the
manager runs whatever job it is handed, so a new command is a new class here.
"""

from __future__ import annotations

import logging
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, Protocol

from explaindrive.commands import Command
from explaindrive.redact import redact
from explaindrive.ride.config import RideConfig
from explaindrive.ride.inputs import PassengerInput, SpokenLine
from explaindrive.ride.session import RideSession
from explaindrive.web.board import RideBoard, RideState
from explaindrive.web.models import StartRequest
from explaindrive.web.uploads import UploadTracker

log = logging.getLogger(__name__)

MAX_WAITING_UPLOADS = 4  # recordings stored and not yet transcribed
PAGE_INTERPRET_DEADLINE_S = RideConfig().audio_deadline_s
"""[s] The typed-request deadline of a ride on the page. That ride is paced and never waits
on language, so a typed request is given as long as a spoken one
(:attr:`RideConfig.audio_deadline_s`); a terminal ride fast-forwards and pauses for a typed
request at most :attr:`RideConfig.interpret_deadline_s`."""


class RideConflictError(RuntimeError):
    """The request does not fit the ride's current state (HTTP 409)."""


class RideStartError(RuntimeError):
    """The ride could not be started (models, policies or SUMO; HTTP 503)."""


class RideBusyError(RuntimeError):
    """Too many recordings are waiting to be transcribed (HTTP 429)."""


class RideWorker(Protocol):
    """The worker's side of the ride manager, which jobs act through."""

    @property
    def board(self) -> RideBoard:
        """What the pages see."""
        ...

    @property
    def uploads(self) -> UploadTracker:
        """The recordings waiting to be transcribed."""
        ...

    def active_session(self) -> RideSession:
        """The running or paused ride (:class:`RideConflictError` when there is none)."""
        ...

    def open_session(self, config: RideConfig) -> RideSession:
        """Build the ride's session with ``config`` and make it the current one."""
        ...

    def end_session(self) -> None:
        """Close the current session, if any, and forget waiting recordings."""
        ...

    def pace_from_now(self) -> None:
        """The next control step is due now."""
        ...


class RideJob(ABC):
    """A command for the ride, run on the worker thread."""

    @abstractmethod
    def run(self, ride: RideWorker) -> dict[str, Any]:
        """Do the command; returns the answer to the page.

        Raises:
            RideConflictError: if the command does not fit the ride's state.
        """


@dataclass(frozen=True)
class Start(RideJob):
    """Start a new ride with ``settings``."""

    settings: StartRequest

    def run(self, ride: RideWorker) -> dict[str, Any]:
        """Load the ride and drive it (:class:`RideStartError` if it cannot start)."""
        board = ride.board
        if board.state in (RideState.RUNNING, RideState.PAUSED, RideState.STARTING):
            raise RideConflictError(f"a ride is already {board.state.value}; reset it first")
        ride.end_session()
        config = RideConfig(
            traffic_level=self.settings.traffic_level,
            seed=self.settings.seed,
            max_steps=self.settings.max_steps,
            realtime=True,
            interpret_deadline_s=PAGE_INTERPRET_DEADLINE_S,
        )
        board.begin(self.settings)
        try:
            session = ride.open_session(config)
            session.start(Command.parse(self.settings.command))
        except Exception as exc:
            log.error("the ride could not start: %s", exc)
            log.debug("start failure", exc_info=True)
            ride.end_session()
            board.fail(redact(f"{type(exc).__name__}: {exc}"))
            raise RideStartError(redact(f"the ride could not start: {exc}")) from exc
        ride.pace_from_now()
        board.set_state(RideState.RUNNING)
        return board.status()


@dataclass(frozen=True)
class Pause(RideJob):
    """Pause the running ride."""

    def run(self, ride: RideWorker) -> dict[str, Any]:
        """Stop stepping until :class:`Resume`."""
        if ride.board.state is not RideState.RUNNING:
            raise RideConflictError(
                f"only a running ride can be paused (the ride is {ride.board.state})"
            )
        ride.board.set_state(RideState.PAUSED)
        return ride.board.status()


@dataclass(frozen=True)
class Resume(RideJob):
    """Resume the paused ride."""

    def run(self, ride: RideWorker) -> dict[str, Any]:
        """Step again from now on."""
        if ride.board.state is not RideState.PAUSED:
            raise RideConflictError(
                f"only a paused ride can resume (the ride is {ride.board.state})"
            )
        ride.pace_from_now()
        ride.board.set_state(RideState.RUNNING)
        return ride.board.status()


@dataclass(frozen=True)
class Reset(RideJob):
    """End the ride and forget it."""

    def run(self, ride: RideWorker) -> dict[str, Any]:
        """Close the session and clear the board."""
        ride.end_session()
        ride.board.clear()
        ride.board.set_state(RideState.IDLE)
        return ride.board.status()


@dataclass(frozen=True)
class Hear(RideJob):
    """A passenger line from the page: typed, or recorded and stored in an upload file."""

    line: PassengerInput

    def run(self, ride: RideWorker) -> dict[str, Any]:
        """Hand the line to the ride (:meth:`RideSession.hear`, as the terminal's lines);
        answers its request id (:class:`RideBusyError` when too many recordings wait)."""
        session = ride.active_session()
        if isinstance(self.line, SpokenLine):
            if ride.uploads.waiting() >= MAX_WAITING_UPLOADS:
                raise RideBusyError(
                    f"{MAX_WAITING_UPLOADS} recordings are still being transcribed; try again soon"
                )
            ride.uploads.add(self.line.audio)
        return {"id": session.hear(self.line)}


@dataclass(frozen=True)
class Answer(RideJob):
    """The passenger's yes or no to the pending question."""

    yes: bool

    def run(self, ride: RideWorker) -> dict[str, Any]:
        """Answer the question (:class:`RideConflictError` when none is pending)."""
        session = ride.active_session()
        pending = session.pending_confirmation
        if pending is None:
            raise RideConflictError("no confirmation question is pending")
        session.answer(self.yes)
        ride.board.clear_question()
        ride.board.publish_status()
        return {"id": pending.id, "answer": "yes" if self.yes else "no"}
