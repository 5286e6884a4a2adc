"""The action space: a change of the ego speed per 1 s decision step.

With the speed limiter (Intelligent Speed Assistance, as new cars in the EU carry it; the
``passenger`` preset's ``speed_limiter``), a rise that would pass the posted limit lands on
the limit instead (:func:`limited_speed`): whole-m/s changes can then hold 13.89 m/s. It
does not brake, but above the limit (past a sign of a lower one) it cuts the throttle: a car
that keeps or raises its speed there slows by :data:`LIMITER_COAST_MPS` a step, down to the
limit. So a car held at the limit whose speed estimate reads a little above it is not made to
brake. The ``paper`` preset keeps the paper's dynamics (no limiter); speeding is judged on the
true speed either way.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

SPEED_CHANGES_MPS: tuple[int, ...] = (-3, -2, -1, 0, 1, 2, 3)  # [m/s] per step
N_ACTIONS = len(SPEED_CHANGES_MPS)
STEP_LENGTH_S = 1.0  # [s] decision step = SUMO step
IDLE_ACTION = SPEED_CHANGES_MPS.index(0)
MAX_BRAKE_MPS = -min(SPEED_CHANGES_MPS)  # [m/s per step] the strongest braking action
STOP_MARGIN_M = 2.0  # [m] the gap a car braking hardest keeps before where it must stand
SPEEDS_KEPT = 1024  # speeds whose results the one-speed helpers keep
LIMITER_COAST_MPS = 1.0  # [m/s per step] above the limit the limiter's throttle cut slows by


def speed_change(action: object) -> int:
    """Speed change [m/s] of a discrete action index (an int or a numpy integer).

    Raises:
        ValueError: if ``action`` is not an integer in ``range(N_ACTIONS)``.
    """
    try:
        index = int(action)  # type: ignore[call-overload]
    except (TypeError, ValueError):
        index = -1
    if isinstance(action, bool) or index != action or not 0 <= index < N_ACTIONS:
        raise ValueError(f"action {action!r} is outside the action space Discrete({N_ACTIONS})")
    return SPEED_CHANGES_MPS[index]


def action_index(change_mps: int) -> int:
    """Inverse of :func:`speed_change`.

    Raises:
        ValueError: if ``change_mps`` is not one of :data:`SPEED_CHANGES_MPS`.
    """
    if change_mps not in SPEED_CHANGES_MPS:
        raise ValueError(f"speed change {change_mps!r} is not one of {SPEED_CHANGES_MPS}")
    return SPEED_CHANGES_MPS.index(change_mps)


def limited_speed(v_mps: float, change_mps: float, limit_mps: float | None) -> float:
    """[m/s] The speed after a change of ``change_mps`` from ``v_mps``, clipped at 0; with a
    posted limit ``limit_mps`` (the speed limiter on), a keep or a rise that would end above
    the limit lands on it, or, from above it, :data:`LIMITER_COAST_MPS` lower but not below
    it (``None``: no limiter)."""
    v_new = max(0.0, v_mps + change_mps)
    if limit_mps is not None and change_mps >= 0 and v_new > limit_mps:
        return max(limit_mps, v_mps - LIMITER_COAST_MPS)
    return v_new


def limited_change(v_mps: float, change_mps: int, limit_mps: float | None) -> float:
    """[m/s] The speed change the speed limiter lets through of ``change_mps`` at ``v_mps``:
    the change itself, except that a keep or a rise that would end above ``limit_mps``
    becomes ``limit - v``, but no less than ``-LIMITER_COAST_MPS`` (:func:`limited_speed`).
    ``None``: no limiter, the change itself. The clip at
    standstill is not the limiter's and is not applied here (braking from 1 m/s by 3 m/s
    stays -3)."""
    if limit_mps is not None and change_mps >= 0 and v_mps + change_mps > limit_mps:
        return max(limit_mps - v_mps, -LIMITER_COAST_MPS)
    return change_mps


def next_speed(v_mps: float, action: int, limit_mps: float | None = None) -> float:
    """Ego speed after applying ``action`` for one step, clipped at 0; with ``limit_mps``,
    through the speed limiter (:func:`limited_speed`)."""
    return limited_speed(v_mps, speed_change(action), limit_mps)


def braking_distances(
    speed_mps: NDArray[np.floating] | float, brake_mps: float = MAX_BRAKE_MPS
) -> NDArray[np.float64]:
    """Distances [m] covered after this step when braking by ``brake_mps`` per 1 s step.

    SUMO moves a car by its new speed each step, so from ``v`` the car covers
    (v - b) + (v - 2b) + ... (the positive terms) while braking to a standstill:
    with n = ceil(v / b) - 1 terms that is n v - b n (n + 1) / 2.
    """
    v = np.maximum(np.asarray(speed_mps, dtype=np.float64), 0.0)
    n = np.maximum(np.ceil(v / brake_mps) - 1.0, 0.0)
    return n * v - brake_mps * n * (n + 1.0) / 2.0


def braking_distance(speed_mps: float, brake_mps: float = MAX_BRAKE_MPS) -> float:
    """:func:`braking_distances` of one speed."""
    return float(braking_distances(np.asarray(speed_mps), brake_mps))


def stopping_needs(v_new: NDArray[np.floating]) -> NDArray[np.float64]:
    """[m] a car needs ahead of its front to stand still, braking hardest after a step that
    leaves it at ``v_new``: that step, the braking and :data:`STOP_MARGIN_M`; 0 for a car
    that stands still after the step (it moves no further)."""
    v = np.asarray(v_new, dtype=np.float64)
    return np.where(v > 0.0, v + braking_distances(v) + STOP_MARGIN_M, 0.0)


@lru_cache(maxsize=SPEEDS_KEPT)
def stopping_need(v_new: float) -> float:
    """:func:`stopping_needs` of one speed (kept per speed: an episode's speeds repeat)."""
    return float(stopping_needs(np.asarray(v_new)))


def least_stopping_needs(speed_mps: NDArray[np.floating]) -> NDArray[np.float64]:
    """[m] cars at ``speed_mps`` need ahead of their front to stand still, braking hardest
    from now on: :func:`stopping_needs` after a hardest-braking step."""
    v = np.asarray(speed_mps, dtype=np.float64)
    return stopping_needs(np.maximum(v - MAX_BRAKE_MPS, 0.0))


@lru_cache(maxsize=SPEEDS_KEPT)
def least_stopping_need(speed_mps: float) -> float:
    """:func:`least_stopping_needs` of one speed (kept per speed: an episode's speeds
    repeat)."""
    return float(least_stopping_needs(np.asarray(speed_mps)))


def stops_before(
    speed_mps: NDArray[np.floating], distance_m: NDArray[np.floating]
) -> NDArray[np.bool_]:
    """Whether cars at ``speed_mps`` can still stand :data:`STOP_MARGIN_M` before lines
    ``distance_m`` ahead by braking hardest from now on (outside a yellow's dilemma zone)."""
    return least_stopping_needs(speed_mps) <= np.asarray(distance_m)


def can_stop_before(speed_mps: float, distance_m: float) -> bool:
    """:func:`stops_before` of one car and line."""
    return bool(stops_before(np.asarray(speed_mps), np.asarray(distance_m)))
