"""LLM-2 shared pieces: decisions, safety factors and the grounded rule engine.

The rules follow the paper's three principles for the decision prompt:

1. explain only when the action clearly conflicts with, or delays, the request for a
   clear safety reason (decelerating under *fast*; harsh braking or acceleration under
   *comfort*);
   with the ride's history (:mod:`~explaindrive.language.explanation.history`), also what
   a passenger notices over several steps: under *fast* a delay that lasts
   (:data:`NOTICED_DELAY_S` well under the limit) or a drop in speed one feels
   (:data:`FELT_DROP_MPS`), explained by a slower car ahead as well as by a hazard; under
   *fast* or *comfort* a standstill that lasts (:data:`LASTING_STANDSTILL_S`), explained by
   what holds the car (:func:`holding_factors`);
2. never for ordinary, supportive or neutral behaviour;
3. with several reasons, keep the most safety-critical one: the hazard the car has to
   act on first (:mod:`explaindrive.language.explanation.hazards` ranks them by urgency).

A yield line where the car must give way to a foe with priority (``d_yield``) is a stop
line like a red light's: braking or standing for it is explained as giving way at the
junction (:attr:`Factor.GIVE_WAY`), never as a vehicle ahead.

Only objects within the cut-off (50 m) count.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from enum import StrEnum

from explaindrive.commands import Command
from explaindrive.language.explanation.hazards import (
    AT_LIMIT_MARGIN_MPS,
    HAZARD_COMFORT_DECEL_MPS2,
    HOLD_MARGIN_MPS,
    MIN_GAP_M,
    SHORT_HEADWAY_S,
    SHORT_TTC_S,
    Factor,
    braking_hazards,
    leader_explains_firm_braking,
    leader_is_hazard,
    stopping_distance_m,
)
from explaindrive.language.explanation.history import SLOW_MARGIN_MPS
from explaindrive.language.explanation.summary import SUMMARY_CUTOFF_M, RecordState, StateRecord

__all__ = [
    "AT_LIMIT_MARGIN_MPS",
    "EXPLAIN_TAG",
    "FELT_DROP_MPS",
    "HAZARD_COMFORT_DECEL_MPS2",
    "HOLD_MARGIN_MPS",
    "LASTING_STANDSTILL_S",
    "MIN_GAP_M",
    "NOTICED_DELAY_S",
    "NO_EXPLANATION_TAG",
    "SHORT_HEADWAY_S",
    "SHORT_TTC_S",
    "Conflict",
    "Decision",
    "ExplanationDecider",
    "Factor",
    "acceleration_factors",
    "braking_factors",
    "detect_conflict",
    "holding_factors",
    "lasting_standstill",
    "leader_is_hazard",
    "most_critical_factor",
    "noticed_delay",
    "parse_decision_tag",
    "rule_decision",
]

NOTICED_DELAY_S = 5.0
"""[s] under fast, driving well under the limit this long is a delay a passenger notices."""
FELT_DROP_MPS = 3.0
"""[m/s] under fast, losing this much speed within the history's window is a drop one feels
(1 m/s^2 on average over 3 s)."""
LASTING_STANDSTILL_S = 5.0
"""[s] standing this long is a wait a passenger notices."""

EXPLAIN_TAG = "[EXPLAIN]"
NO_EXPLANATION_TAG = "[NO EXPLANATION NEEDED]"


class Conflict(StrEnum):
    """How an action goes against the request."""

    NONE = "none"
    SLOWS = "slows"  # braking or holding back although the passenger asked for more speed
    HARSH_BRAKING = "harsh_braking"
    HARSH_ACCELERATION = "harsh_acceleration"
    WAITS = "waits"  # standing for a while although the passenger did not ask to stop


@dataclass(frozen=True, slots=True)
class Decision:
    """Outcome of LLM-2 for one step.

    Attributes:
        explain: whether to explain the action to the passenger (tag ``[EXPLAIN]``).
        factor: the most safety-critical factor (when ``explain``), else ``None``.
        conflict: how the action goes against the request (``none`` if it does not).
        reason: a short human-readable trace of the decision.
        backend: backend that answered; ``fallback`` when ``embedded`` stood in.
        latency_s: wall time of the call [s].
        error: why the configured backend was bypassed, when ``fallback``.
        vetoed: a remote ``[EXPLAIN]`` was overruled because the state holds no conflict
            with the request or no safety factor to name.
        raw_reply: the remote model's reply as it came (for the ride log only).
    """

    explain: bool
    factor: Factor | None
    conflict: Conflict
    reason: str
    backend: str
    fallback: bool = False
    latency_s: float = 0.0
    error: str | None = None
    vetoed: bool = False
    raw_reply: str | None = None

    @property
    def tag(self) -> str:
        """The paper's output tag for this decision."""
        return EXPLAIN_TAG if self.explain else NO_EXPLANATION_TAG


class ExplanationDecider(ABC):
    """LLM-2: decides whether an action needs explaining."""

    name: str = "abstract"

    @abstractmethod
    def decide(self, record: StateRecord) -> Decision:
        """Decide for one state record (never raises on a valid record)."""


def parse_decision_tag(text: str) -> bool | None:
    """``True`` for ``[EXPLAIN]``, ``False`` for ``[NO EXPLANATION NEEDED]``, else ``None``.

    The reply must be exactly one tag (white space around it and case are tolerated).
    """
    reply = text.strip().upper()
    if reply == EXPLAIN_TAG:
        return True
    if reply == NO_EXPLANATION_TAG:
        return False
    return None


def detect_conflict(record: StateRecord, cutoff_m: float = SUMMARY_CUTOFF_M) -> Conflict:
    """How the record's action goes against its request (principles 1 and 2)."""
    s = record.nearby(cutoff_m)
    a = record.action
    if record.command is Command.FAST:
        if a < 0 or (a == 0 and s.v_ego < s.v_lim - HOLD_MARGIN_MPS):
            return Conflict.SLOWS
    elif record.command is Command.COMFORT:
        if a <= -2:
            return Conflict.HARSH_BRAKING
        if a >= 2:
            return Conflict.HARSH_ACCELERATION
        if lasting_standstill(record):
            return Conflict.WAITS
    # STOP: braking or standing is the request itself; the driving policy never has a
    # safety reason in the state to keep going, so there is nothing to justify.
    return Conflict.NONE


def noticed_delay(record: StateRecord) -> bool:
    """Under fast, whether the passenger notices a delay the step's action keeps up: slow
    for :data:`NOTICED_DELAY_S` or a speed drop of :data:`FELT_DROP_MPS` (history needed)."""
    h = record.history
    if h is None or record.command is not Command.FAST or record.action > 0:
        return False
    return h.slow_s >= NOTICED_DELAY_S or h.drop_mps >= FELT_DROP_MPS


def lasting_standstill(record: StateRecord) -> bool:
    """Under fast or comfort, whether the car has stood for :data:`LASTING_STANDSTILL_S`."""
    h = record.history
    return (
        h is not None
        and record.command is not Command.STOP
        and record.action <= 0
        and h.stopped_s >= LASTING_STANDSTILL_S
    )


def holding_factors(s: RecordState) -> list[Factor]:
    """What holds the car back, nearest first: an occupied crossing, a red or yellow light,
    a yield line where it must give way, a leader slower than
    :data:`~explaindrive.language.explanation.history.SLOW_MARGIN_MPS` under the limit (a
    stopped one: a queue). ``s`` holds only objects within the cut-off."""
    found: list[tuple[float, Factor]] = []
    if s.d_cross is not None:
        found.append((s.d_cross, Factor.PEDESTRIAN))
    if s.tl_state in ("red", "yellow") and s.d_tl is not None:
        found.append((s.d_tl, Factor.TRAFFIC_LIGHT))
    if s.d_yield is not None:
        found.append((s.d_yield, Factor.GIVE_WAY))
    if s.d_lead is not None and s.v_ego - (s.dv or 0.0) <= s.v_lim - SLOW_MARGIN_MPS:
        found.append((s.d_lead, Factor.LEAD_VEHICLE))
    return [f for _, f in sorted(found, key=lambda x: x[0])]


def braking_factors(s: RecordState) -> list[Factor]:
    """Safety reasons for slowing down, most urgent first (see
    :func:`~explaindrive.language.explanation.hazards.braking_hazards`)."""
    return [h.factor for h in braking_hazards(s)]


def acceleration_factors(s: RecordState) -> list[Factor]:
    """Safety reasons for accelerating firmly: a yellow light too close to stop comfortably."""
    if s.tl_state == "yellow" and s.d_tl is not None and s.d_tl < stopping_distance_m(s.v_ego):
        return [Factor.TRAFFIC_LIGHT]
    return []


def rule_decision(record: StateRecord, cutoff_m: float = SUMMARY_CUTOFF_M) -> Decision:
    """The grounded rule engine: the embedded LLM-2 (latency and backend filled by callers)."""
    conflict = detect_conflict(record, cutoff_m)
    if conflict is Conflict.NONE:
        return Decision(
            False, None, conflict, "action is ordinary or supports the request", backend="embedded"
        )
    s = record.nearby(cutoff_m)
    factors = _candidates(conflict, record, s)
    if not factors:
        return Decision(
            False,
            None,
            conflict,
            f"{conflict.value} but no safety reason within {cutoff_m:g} m",
            backend="embedded",
        )
    names = ", ".join(f.value for f in factors)
    return Decision(
        True,
        factors[0],
        conflict,
        f"{conflict.value} for {factors[0].value} (candidates: {names})",
        backend="embedded",
    )


def _candidates(conflict: Conflict, record: StateRecord, s: RecordState) -> list[Factor]:
    """The factors that may explain the conflict, the one to name first."""
    if conflict is Conflict.HARSH_ACCELERATION:
        return acceleration_factors(s)
    if conflict is Conflict.WAITS:
        return holding_factors(s)
    factors = braking_factors(s)
    if conflict is not Conflict.SLOWS:
        return factors
    if Factor.LEAD_VEHICLE not in factors and leader_explains_firm_braking(s, record.action):
        factors.append(Factor.LEAD_VEHICLE)  # firm braking for a leader not yet close
    if noticed_delay(record):
        factors += [f for f in holding_factors(s) if f not in factors]
    return factors


def most_critical_factor(record: StateRecord, cutoff_m: float = SUMMARY_CUTOFF_M) -> Factor | None:
    """The factor to explain: the rule engine's choice, else the first braking factor."""
    decision = rule_decision(record, cutoff_m)
    if decision.factor is not None:
        return decision.factor
    factors = braking_factors(record.nearby(cutoff_m))
    return factors[0] if factors else None
