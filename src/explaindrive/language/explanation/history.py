"""What the passenger has felt up to a step: how long the car has been slow or standing,
and how much speed it has just lost.

A single state shows what the car does now; a passenger notices what lasts. A ride keeps a
:class:`HistoryTracker` and hands each step's :class:`RideHistory` to LLM-2 with the state
record, so the decider can explain a delay that lasts, a drop in speed one feels and a
standstill (:mod:`~explaindrive.language.explanation.decision`).

* ``slow_s``: seconds in a row the car has driven at least :data:`SLOW_MARGIN_MPS` under
  the limit (standing included);
* ``stopped_s``: seconds in a row it has stood still (at most :data:`STOPPED_MPS`);
* ``drop_mps``: speed lost since the fastest of the last :data:`DROP_WINDOW_S` seconds.
"""

from __future__ import annotations

from collections import deque

from pydantic import BaseModel, ConfigDict, Field

SLOW_MARGIN_MPS = 3.0
"""[m/s] driving this far under the limit is slow enough for a passenger to notice
(11 km/h: 39 km/h on a 50 km/h road)."""
STOPPED_MPS = 0.5
"""[m/s] in the state seen, the car stands still at or below this (the explanations'
``SEEN_STANDSTILL_MPS``)."""
DROP_WINDOW_S = 3
"""[s] the window a speed drop is measured over."""


class RideHistory(BaseModel):
    """What the passenger has felt up to a step (see the module docstring)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    slow_s: float = Field(default=0.0, ge=0.0)  # [s]
    stopped_s: float = Field(default=0.0, ge=0.0)  # [s]
    drop_mps: float = Field(default=0.0, ge=0.0)  # [m/s]


class HistoryTracker:
    """Keeps a ride's :class:`RideHistory` from the speeds and limits it sees.

    Args:
        step_s: length of a step [s].
    """

    def __init__(self, step_s: float = 1.0) -> None:
        self.step_s = step_s
        self._slow_s = 0.0
        self._stopped_s = 0.0
        self._recent: deque[float] = deque(maxlen=int(DROP_WINDOW_S / step_s) + 1)

    def update(self, v_mps: float, v_lim_mps: float) -> RideHistory:
        """Take the speed seen at the end of a step and the limit; return the history."""
        slow = v_mps <= v_lim_mps - SLOW_MARGIN_MPS
        self._slow_s = self._slow_s + self.step_s if slow else 0.0
        self._stopped_s = self._stopped_s + self.step_s if v_mps <= STOPPED_MPS else 0.0
        self._recent.append(v_mps)
        drop = max(self._recent) - v_mps
        return RideHistory(
            slow_s=self._slow_s, stopped_s=self._stopped_s, drop_mps=round(max(drop, 0.0), 2)
        )
