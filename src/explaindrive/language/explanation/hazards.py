"""Safety factors of a state and how urgent each one is.

With several hazards present, the one that forces the action is the one the car has to
act on first. Each hazard gets a *slack*: the time left before the car must start
braking for it at the comfortable deceleration (2 m/s^2), at its current speed.

* a red or yellow light, an occupied pedestrian crossing, or a yield line where the car
  must give way to a foe with priority, at distance ``d``:
  ``(d - v^2 / (2 b)) / v`` — negative once the car is inside the stopping distance
  the stop line needs;
* a leader closing at ``dv``: ``(gap - standstill gap - dv^2 / (2 b)) / dv`` — the
  time before the car must brake to match its speed; a leader that is not closing:
  the time headway ``gap / v``;
* the speed limit: no slack to run out (it explains braking only when nothing else does).

Speeds under 1 m/s count as 1 m/s, so a waiting car ranks what is nearest. Ties keep
the order pedestrian, leader, light, yield line, limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from typing import Protocol

HOLD_MARGIN_MPS = 1.0  # [m/s] holding speed this far below the limit delays a "fast" request
AT_LIMIT_MARGIN_MPS = 0.5  # [m/s] within this of the limit the limit explains braking
SHORT_HEADWAY_S = 2.0  # [s] time headway below which the leader is a safety reason
SHORT_TTC_S = 5.0  # [s] time to collision below which the leader is a safety reason
MIN_GAP_M = 10.0  # [m] a leader closer than this is always a safety reason
HAZARD_COMFORT_DECEL_MPS2 = 2.0  # [m/s^2] comfortable braking, in explanations
STANDSTILL_GAP_M = 2.0  # [m] gap kept to a stopped leader
MIN_SPEED_MPS = 1.0  # [m/s] slower speeds count as this when timing a hazard
CLOSING_MPS = 0.1  # [m/s] a leader is closing when the gap shrinks faster than this
FIRM_BRAKE_MPS = -2  # [m/s] speed changes at or below this are firm or hard braking
FIRM_BRAKE_HEADWAY_S = 4.0  # [s] a leader within this headway explains firm braking


class Factor(StrEnum):
    """A safety-relevant factor an explanation can name."""

    TRAFFIC_LIGHT = "traffic_light"
    PEDESTRIAN = "pedestrian"
    LEAD_VEHICLE = "lead_vehicle"
    GIVE_WAY = "give_way"  # a junction where a foe with priority passes first
    SPEED_LIMIT = "speed_limit"


_TIE_ORDER = (
    Factor.PEDESTRIAN,
    Factor.LEAD_VEHICLE,
    Factor.TRAFFIC_LIGHT,
    Factor.GIVE_WAY,
    Factor.SPEED_LIMIT,
)


class _State(Protocol):
    """The fields of :class:`~explaindrive.language.explanation.summary.RecordState` read here."""

    @property
    def v_ego(self) -> float: ...
    @property
    def v_lim(self) -> float: ...
    @property
    def d_lead(self) -> float | None: ...
    @property
    def dv(self) -> float | None: ...
    @property
    def d_tl(self) -> float | None: ...
    @property
    def tl_state(self) -> str | None: ...
    @property
    def d_cross(self) -> float | None: ...
    @property
    def d_yield(self) -> float | None: ...


@dataclass(frozen=True, slots=True)
class Hazard:
    """A factor that gives the car a reason to slow down, with its urgency.

    Attributes:
        factor: which factor.
        slack_s: time left before the car must brake for it [s] (negative: it is
            already inside the distance it needs); ``inf`` for the speed limit.
        distance_m: how far ahead it is [m] (``None`` for the speed limit).
    """

    factor: Factor
    slack_s: float
    distance_m: float | None


def stopping_distance_m(v_mps: float) -> float:
    """Distance to stop from ``v_mps`` at the comfortable deceleration [m]."""
    return v_mps**2 / (2.0 * HAZARD_COMFORT_DECEL_MPS2)


def stop_line_slack_s(distance_m: float, v_mps: float) -> float:
    """Time before the car must brake to stop comfortably at ``distance_m`` [s]."""
    return (distance_m - stopping_distance_m(v_mps)) / max(v_mps, MIN_SPEED_MPS)


def headway_s(s: _State) -> float:
    """Time headway to the leader [s] (``inf`` without one or when standing)."""
    if s.d_lead is None or s.v_ego <= 0.1:
        return math.inf
    return s.d_lead / s.v_ego


def ttc_s(s: _State) -> float:
    """Time to collision with the leader [s] (``inf`` when it is not closing)."""
    dv = s.dv or 0.0
    if s.d_lead is None or dv <= CLOSING_MPS:
        return math.inf
    return s.d_lead / dv


def leader_slack_s(s: _State) -> float:
    """Time before the car must brake for its leader [s] (``inf`` without one)."""
    if s.d_lead is None:
        return math.inf
    dv = s.dv or 0.0
    if dv > CLOSING_MPS:
        return (s.d_lead - STANDSTILL_GAP_M - dv**2 / (2.0 * HAZARD_COMFORT_DECEL_MPS2)) / dv
    return s.d_lead / max(s.v_ego, MIN_SPEED_MPS)


def leader_is_hazard(s: _State) -> bool:
    """Whether the leader is close enough (gap, headway or TTC) to be a safety reason."""
    if s.d_lead is None:
        return False
    return s.d_lead < MIN_GAP_M or headway_s(s) < SHORT_HEADWAY_S or ttc_s(s) < SHORT_TTC_S


def leader_explains_firm_braking(s: _State, action: int) -> bool:
    """Whether the leader explains braking at ``action`` although it is no hazard yet.

    A driving policy brakes firmly well before the leader is close: behind a leader that
    is closing, or within :data:`FIRM_BRAKE_HEADWAY_S`, firm or hard braking
    (``action <= FIRM_BRAKE_MPS``) is explained by it. ``s`` holds only objects within the
    cut-off.
    """
    if s.d_lead is None or action > FIRM_BRAKE_MPS:
        return False
    return (s.dv or 0.0) > CLOSING_MPS or headway_s(s) < FIRM_BRAKE_HEADWAY_S


def braking_hazards(s: _State) -> list[Hazard]:
    """Reasons to slow down present in ``s``, most urgent first.

    A reason is an occupied crossing, a red or yellow light, a yield line in force, a
    leader that is close (:func:`leader_is_hazard`) or being at the speed limit; ``s`` is
    expected to hold only objects within the cut-off.
    """
    v = s.v_ego
    found: list[Hazard] = []
    if s.d_cross is not None:
        found.append(Hazard(Factor.PEDESTRIAN, stop_line_slack_s(s.d_cross, v), s.d_cross))
    if leader_is_hazard(s):
        found.append(Hazard(Factor.LEAD_VEHICLE, leader_slack_s(s), s.d_lead))
    if s.tl_state in ("red", "yellow") and s.d_tl is not None:
        found.append(Hazard(Factor.TRAFFIC_LIGHT, stop_line_slack_s(s.d_tl, v), s.d_tl))
    if s.d_yield is not None:
        found.append(Hazard(Factor.GIVE_WAY, stop_line_slack_s(s.d_yield, v), s.d_yield))
    if v >= s.v_lim - AT_LIMIT_MARGIN_MPS:
        found.append(Hazard(Factor.SPEED_LIMIT, math.inf, None))
    return sorted(found, key=lambda h: (h.slack_s, _TIE_ORDER.index(h.factor)))
