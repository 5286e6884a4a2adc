"""The language lane: language work off the control path, each task with a deadline.

Work runs in two channels of worker threads, so that explanations never delay or starve
the passenger's requests:

* ``interpretation`` (transcription and LLM-1): several workers, so a line never waits
  behind an earlier one that a slow model still holds;
* ``explanation`` (LLM-2 and LLM-3): one worker, its tasks in order.

The control loop polls for finished tasks; a task that misses its deadline is reported
as late and its result, if it ever comes, is dropped. A task carries the ride's typed job
(:data:`~explaindrive.ride.jobs.LanguageJob`) and returns a typed result
(:data:`~explaindrive.ride.jobs.LanguageResult`).
"""

from __future__ import annotations

import concurrent.futures as cf
import time
from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from explaindrive.ride.jobs import LanguageJob, LanguageResult

INTERPRETATION = "interpretation"
EXPLANATION = "explanation"


class TaskKind(StrEnum):
    """The kinds of language work."""

    INTERPRET = "interpret"
    TRANSCRIBE = "transcribe"
    DECIDE = "decide"
    EXPLAIN = "explain"


CHANNELS: dict[TaskKind, str] = {
    TaskKind.INTERPRET: INTERPRETATION,
    TaskKind.TRANSCRIBE: INTERPRETATION,
    TaskKind.DECIDE: EXPLANATION,
    TaskKind.EXPLAIN: EXPLANATION,
}
"""The channel of each kind of task."""
INTERPRETATION_WORKERS = 4  # lines interpreted at the same time before one has to wait

Finished = tuple[LanguageResult | None, str | None, float]
"""What a worker hands back: the result, the error message, the monotonic finish time [s]."""


@dataclass
class Task:
    """A piece of language work."""

    kind: TaskKind
    future: cf.Future[Finished]
    submitted: float  # [s] monotonic wall time
    deadline_s: float  # [s] allowed wall time
    context: LanguageJob | None = None
    """What the submitter needs back with the result (a ride's typed job)."""

    @property
    def expires(self) -> float:
        """Monotonic time after which the task is late."""
        return self.submitted + self.deadline_s

    @property
    def channel(self) -> str:
        """The channel the task runs in."""
        return CHANNELS[self.kind]


@dataclass(frozen=True)
class Outcome:
    """A finished (or late, or failed) task."""

    task: Task
    result: LanguageResult | None = None
    """``None`` when the task was late or failed."""
    error: str | None = None
    late: bool = False
    latency_s: float = 0.0


class LanguageLane:
    """Runs language tasks in an interpretation and an explanation channel, with deadlines.

    Args:
        interpretation_workers: threads of the interpretation channel.
    """

    def __init__(self, interpretation_workers: int = INTERPRETATION_WORKERS) -> None:
        self._pools = {
            INTERPRETATION: cf.ThreadPoolExecutor(
                max_workers=interpretation_workers, thread_name_prefix="language-interpret"
            ),
            EXPLANATION: cf.ThreadPoolExecutor(
                max_workers=1, thread_name_prefix="language-explain"
            ),
        }
        self._pending: list[Task] = []
        self._overdue: list[Task] = []  # late tasks whose worker may still be running

    @property
    def pending(self) -> int:
        """Tasks submitted and not yet collected."""
        return len(self._pending)

    def pending_kind(self, kind: TaskKind | str) -> bool:
        """Whether a task of ``kind`` is pending."""
        return any(t.kind == kind for t in self._pending)

    def working(self) -> set[TaskKind]:
        """The kinds of task a worker is still running (finished ones waiting to be
        collected are not counted)."""
        return {t.kind for t in self._pending if not t.future.done()}

    def busy(self, channel: str) -> bool:
        """Whether ``channel`` has a task that is pending or still running after its deadline."""
        return any(t.channel == channel for t in self._pending) or any(
            not t.future.done() for t in self._overdue if t.channel == channel
        )

    def submit(
        self,
        kind: TaskKind | str,
        fn: Callable[..., LanguageResult],
        *args: Any,
        deadline_s: float,
        context: LanguageJob | None = None,
    ) -> Task:
        """Queue ``fn(*args)`` in the channel of ``kind``; it must finish within
        ``deadline_s`` wall seconds.

        Raises:
            ValueError: for a kind of task that no channel runs.
        """
        if kind not in CHANNELS:
            known = sorted(k.value for k in CHANNELS)
            raise ValueError(f"unknown language task {kind!r}; expected one of {known}")
        task_kind = TaskKind(kind)
        submitted = time.monotonic()  # before the worker can start
        future = self._pools[CHANNELS[task_kind]].submit(_run, fn, args)
        task = Task(task_kind, future, submitted, deadline_s, context)
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
                out.append(_finished(task))
            elif now >= task.expires:
                if not task.future.cancel():
                    self._overdue = [*(t for t in self._overdue if not t.future.done()), task]
                out.append(Outcome(task, late=True, latency_s=now - task.submitted))
            else:
                keep.append(task)
        self._pending = keep
        return out

    def close(self) -> None:
        """Stop the workers (pending work is abandoned)."""
        for task in self._pending:
            task.future.cancel()
        self._pending = []
        for pool in self._pools.values():
            pool.shutdown(wait=False, cancel_futures=True)


def _finished(task: Task) -> Outcome:
    """The outcome of a task whose worker has returned (late if it took too long)."""
    value, error, finished = task.future.result()
    latency = finished - task.submitted
    if latency > task.deadline_s:
        return Outcome(task, late=True, latency_s=latency)
    return Outcome(task, result=value, error=error, latency_s=latency)


def _run(fn: Callable[..., LanguageResult], args: tuple[Any, ...]) -> Finished:
    """Run ``fn``; return (result, error message, monotonic finish time); never raises."""
    try:
        value = fn(*args)
    except Exception as exc:  # a failing model must not take the ride down
        return None, f"{type(exc).__name__}: {exc}", time.monotonic()
    return value, None, time.monotonic()
