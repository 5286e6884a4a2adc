"""What the pages see of the ride: its state, history and log, and who is watching.

The ride worker writes the board; web handlers read it from other threads, so every
read and write holds the board's lock. Listeners are called on the worker thread.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from enum import StrEnum
from typing import Any

from explaindrive.web.models import StartRequest

log = logging.getLogger(__name__)

Listener = Callable[[dict[str, Any]], None]

LOG_LIMIT = 200  # passenger events kept for pages that join late


class RideState(StrEnum):
    """Where the ride is."""

    IDLE = "idle"
    STARTING = "starting"
    RUNNING = "running"
    PAUSED = "paused"
    FINISHED = "finished"
    FAILED = "failed"


class RideBoard:
    """The ride as the pages see it, and the listeners that watch it.

    Args:
        step_period_s: wall time between control steps [s] (reported in the status).
    """

    def __init__(self, step_period_s: float) -> None:
        self.step_period_s = step_period_s
        self._lock = threading.Lock()
        self._listeners: list[Listener] = []
        self._state = RideState.IDLE
        self._ride = 0
        self._settings: StartRequest | None = None
        self._error: str | None = None
        self._history: list[dict[str, Any]] = []
        self._explanations: list[dict[str, Any]] = []
        self._log: list[dict[str, Any]] = []
        self._last_frame: dict[str, Any] | None = None
        self._question: str | None = None
        self.explained_steps: set[int] = set()
        """Steps of the current ride whose explanation has been published (worker only)."""

    # ------------------------------------------------------------------ read
    @property
    def state(self) -> RideState:
        """Where the ride is."""
        return self._state

    @property
    def ride(self) -> int:
        """The number of the current ride (1 for the first)."""
        return self._ride

    def status(self) -> dict[str, Any]:
        """The ride's state, settings and pending question."""
        with self._lock:
            return self._status_locked()

    def snapshot(self) -> dict[str, Any]:
        """Everything a page needs to draw the ride so far."""
        with self._lock:
            return self._snapshot_locked()

    # ------------------------------------------------------------------ listeners
    def subscribe(self, listener: Listener) -> dict[str, Any]:
        """Add a listener; returns the snapshot it starts from."""
        with self._lock:
            self._listeners.append(listener)
            return self._snapshot_locked()

    def unsubscribe(self, listener: Listener) -> None:
        """Remove a listener (no error if it is gone)."""
        with self._lock:
            if listener in self._listeners:
                self._listeners.remove(listener)

    @property
    def listener_count(self) -> int:
        """Number of subscribed listeners."""
        with self._lock:
            return len(self._listeners)

    def publish(self, message: dict[str, Any]) -> None:
        """Send ``message`` to every listener; one that fails is removed."""
        with self._lock:
            listeners = list(self._listeners)
        for listener in listeners:
            try:
                listener(message)
            except Exception:
                log.exception("a listener failed; removing it")
                self.unsubscribe(listener)

    def publish_status(self) -> None:
        """Send the status to every listener."""
        self.publish({"type": "status", **self.status()})

    # ------------------------------------------------------------------ write (worker)
    def set_state(self, state: RideState) -> None:
        """Move the ride to ``state`` and tell the listeners."""
        with self._lock:
            self._state = state
        self.publish_status()

    def begin(self, settings: StartRequest) -> None:
        """A new ride with ``settings`` is starting: clear the last one's traces."""
        with self._lock:
            self._ride += 1
            self._settings = settings
            self._state = RideState.STARTING
            self._error = None
            self._history, self._explanations, self._log = [], [], []
            self._last_frame, self._question = None, None
            self.explained_steps = set()
        self.publish_status()

    def clear(self) -> None:
        """Forget the ride's settings and traces (the state is set separately)."""
        with self._lock:
            self._settings, self._error = None, None
            self._history, self._explanations, self._log = [], [], []
            self._last_frame, self._question = None, None

    def fail(self, error: str) -> None:
        """The ride failed with ``error``; tell the listeners."""
        with self._lock:
            self._state = RideState.FAILED
            self._error = error
        self.publish_status()

    def clear_question(self) -> None:
        """The confirmation question was answered."""
        with self._lock:
            self._question = None

    def add_frame(self, frame: dict[str, Any]) -> None:
        """Keep a step's frame in the history and the log, then send it to the listeners."""
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
        self.publish(frame)

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
