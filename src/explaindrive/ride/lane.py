"""The language lane: language work off the control path, each task with a deadline.

Tasks run one at a time in a worker thread. The control loop polls for finished
tasks; a task that misses its deadline is reported as late and its result, if
it ever comes, is dropped.
"""

from __future__ import annotations

import concurrent.futures as cf
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Task:
    """A piece of language work."""

    kind: str  # "interpret", "transcribe", "decide", "explain"
    future: cf.Future[Any]
    submitted: float  # [s] monotonic wall time
    deadline_s: float  # [s] allowed wall time
    context: dict[str, Any] = field(default_factory=dict)

    @property
    def expires(self) -> float:
        """Monotonic time after which the task is late."""
        return self.submitted + self.deadline_s


@dataclass(frozen=True)
class Outcome:
    """A finished (or late, or failed) task."""

    task: Task
    result: Any = None
    error: str | None = None
    late: bool = False
    latency_s: float = 0.0


class LanguageLane:
    """Runs language tasks in one worker thread with per-task deadlines."""

    def __init__(self) -> None:
        self._pool = cf.ThreadPoolExecutor(max_workers=1, thread_name_prefix="language")
        self._pending: list[Task] = []

    @property
    def pending(self) -> int:
        """Tasks submitted and not yet collected."""
        return len(self._pending)

    def pending_kind(self, kind: str) -> bool:
        """Whether a task of ``kind`` is pending."""
        return any(t.kind == kind for t in self._pending)

    def submit(
        self,
        kind: str,
        fn: Callable[..., Any],
        *args: Any,
        deadline_s: float,
        context: dict[str, Any] | None = None,
    ) -> Task:
        """Queue ``fn(*args)``; it must finish within ``deadline_s`` wall seconds."""
        submitted = time.monotonic()  # before the worker can start
        task = Task(kind, self._pool.submit(_run, fn, args), submitted, deadline_s, context or {})
        self._pending.append(task)
        return task

    def collect(self, wait: bool = False) -> list[Outcome]:
        """Finished and late tasks, in submission order.

        Args:
            wait: block until every pending task has finished or passed its deadline
                (used when the simulation runs faster than real time).
        """
        if wait and self._pending:
            latest = max(t.expires for t in self._pending)
            cf.wait([t.future for t in self._pending], timeout=max(0.0, latest - time.monotonic()))
        now = time.monotonic()
        out: list[Outcome] = []
        keep: list[Task] = []
        for task in self._pending:
            if task.future.done() and not task.future.cancelled():
                value, error, finished = task.future.result()
                latency = finished - task.submitted
                if latency > task.deadline_s:
                    out.append(Outcome(task, late=True, latency_s=latency))
                else:
                    out.append(Outcome(task, result=value, error=error, latency_s=latency))
            elif now >= task.expires:
                task.future.cancel()
                out.append(Outcome(task, late=True, latency_s=now - task.submitted))
            else:
                keep.append(task)
        self._pending = keep
        return out

    def close(self) -> None:
        """Stop the worker (pending work is abandoned)."""
        for task in self._pending:
            task.future.cancel()
        self._pending = []
        self._pool.shutdown(wait=False, cancel_futures=True)


def _run(fn: Callable[..., Any], args: tuple[Any, ...]) -> tuple[Any, str | None, float]:
    """Run ``fn``; return (result, error message, monotonic finish time); never raises."""
    try:
        value = fn(*args)
    except Exception as exc:  # a failing model must not take the ride down
        return None, f"{type(exc).__name__}: {exc}", time.monotonic()
    return value, None, time.monotonic()
