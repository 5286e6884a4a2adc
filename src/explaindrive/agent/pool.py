"""What every pool of rollout workers shares: the round's results and the pool's interface.

:mod:`explaindrive.agent.workers` (local pools) and :mod:`explaindrive.agent.ray_pool`
(Ray actors) both build on this module, and neither on the other's internals.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from explaindrive.agent.rollout import CollectRequest, Rollout


@dataclass(frozen=True)
class WorkerLost:
    """A worker died during the round (it has been restarted without an episode)."""

    worker: int
    reason: str


RoundResult = Rollout | WorkerLost


class WorkerPool(Protocol):
    """What the trainer needs from its workers."""

    num_workers: int

    def submit(self, requests: Sequence[CollectRequest]) -> None:
        """Start one round: request ``i`` goes to worker ``i``."""
        ...

    def gather(self) -> list[RoundResult]:
        """Wait for the round; one result per worker, in worker order."""
        ...

    def close(self) -> None:
        """Stop the workers."""
        ...


__all__ = ["RoundResult", "WorkerLost", "WorkerPool"]
