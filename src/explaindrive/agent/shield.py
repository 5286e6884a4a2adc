"""A kinematic safety shield: keeps a policy's greedy choice unless it is unsafe.

Among the actions ordered by Q-value, the shield takes the first one after
which the ego could still stop behind its leader (real or virtual) braking at
-3 m/s per step, even if a real leader brakes at 9 m/s^2 (SUMO's emergency
deceleration), and which does not exceed the posted limit. If no action
qualifies, it brakes as hard as it can. Under STOP it also keeps the stop within
its latency bound (ceil(v/3) + 2 steps from the command).

Red and yellow lights and occupied crossings are stop lines the ego must be able
to stop before; a yellow light that even the hardest braking cannot stop for is
not (the dilemma zone): there the ego goes on without slowing down, since
braking would only leave it on the junction at red.
The shield is off during training; it is a runtime guard in the controller.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from explaindrive.env import state as S
from explaindrive.env.actions import SPEED_CHANGES_MPS, action_index

MAX_BRAKE_MPS = 3  # [m/s per step] the strongest action
LEADER_BRAKE_MPS = 9.0  # [m/s per step] how hard a real leader may brake (SUMO emergency decel)
MARGIN_M = 2.0  # [m] gap kept at standstill
VIRTUAL_TOL_M = 0.5  # [m] a leader this close to a stop line is the virtual leader


def braking_distance(speed_mps: float, brake_mps: float = MAX_BRAKE_MPS) -> float:
    """Distance [m] covered after this step when braking by ``brake_mps`` per 1 s step.

    SUMO moves a car by its new speed each step, so from ``v`` the car covers
    (v - 3) + (v - 6) + ... while braking to a standstill.
    """
    total, v = 0.0, speed_mps - brake_mps
    while v > 0:
        total += v
        v -= brake_mps
    return total


@dataclass(frozen=True, slots=True)
class ShieldDecision:
    """The shielded action and whether the shield overrode the policy."""

    action: int
    overridden: bool


def is_safe(obs: NDArray[np.floating], action: int) -> bool:
    """Whether ``action`` keeps a stopping option and respects the posted limit."""
    v = float(obs[S.V_EGO])
    v_new = max(0.0, v + SPEED_CHANGES_MPS[action])
    if v_new > float(obs[S.V_LIM]) and v_new > v - MAX_BRAKE_MPS + 1e-9:
        return False
    lines, must_go = _stop_lines(obs, v)
    if must_go and v_new < v:
        return False  # committed to a yellow it cannot stop for: clear it quickly
    need = _stopping_need(v_new)
    if any(need > line for line in lines):
        return False
    gap = float(obs[S.D_LEAD])
    if gap >= S.SENSOR_RANGE_M or _is_stop_line(obs, gap):
        return True
    leader_v = max(0.0, v - float(obs[S.DV]))
    return gap + braking_distance(leader_v, LEADER_BRAKE_MPS) >= need


def _stopping_need(v_new: float) -> float:
    """[m] from the ego's front to where it stands still after this step and braking."""
    return v_new + braking_distance(v_new) + MARGIN_M


def _stop_lines(obs: NDArray[np.floating], v: float) -> tuple[list[float], bool]:
    """Stop lines the ego must not pass, and whether it is committed to go.

    Red and yellow lights and occupied crossings are stop lines, except a yellow
    light that even the hardest braking now cannot stop for (the dilemma zone):
    then the ego must go on without slowing down.
    """
    lines = []
    d_cross = float(obs[S.D_CROSS])
    if d_cross < S.SENSOR_RANGE_M:
        lines.append(d_cross)
    tls = round(float(obs[S.TLS]))
    d_tl = float(obs[S.D_TL])
    must_go = False
    if d_tl < S.SENSOR_RANGE_M and tls != 0:
        hardest = max(0.0, v - MAX_BRAKE_MPS)
        must_go = tls == 1 and _stopping_need(hardest) > d_tl
        if not must_go:
            lines.append(d_tl)
    return lines, must_go


def _is_stop_line(obs: NDArray[np.floating], gap: float) -> bool:
    light = round(float(obs[S.TLS])) != 0 and abs(gap - float(obs[S.D_TL])) <= VIRTUAL_TOL_M
    cross = abs(gap - float(obs[S.D_CROSS])) <= VIRTUAL_TOL_M
    return light or cross


def stop_in_time(speed_mps: float, action: int, steps_left: int) -> bool:
    """Whether, after ``action``, braking hardest still reaches 0 m/s within ``steps_left``
    steps (this one included): the STOP latency guarantee."""
    v_new = max(0.0, speed_mps + SPEED_CHANGES_MPS[action])
    return 1 + math.ceil(v_new / MAX_BRAKE_MPS) <= steps_left


def shield(
    obs: NDArray[np.floating],
    q_values: Sequence[float] | NDArray[np.floating],
    stop_steps_left: int | None = None,
) -> ShieldDecision:
    """The best-valued safe action for a raw observation.

    Args:
        obs: raw observation.
        q_values: the policy's Q-values, one per action.
        stop_steps_left: under STOP, the steps left to reach a standstill; actions that
            would miss it are not allowed.
    """
    order = np.argsort(-np.asarray(q_values, dtype=np.float64), kind="stable")
    v = float(obs[S.V_EGO])
    for rank, a in enumerate(order):
        late = (
            stop_steps_left is not None and v > 0 and not stop_in_time(v, int(a), stop_steps_left)
        )
        if not late and is_safe(obs, int(a)):
            return ShieldDecision(int(a), overridden=rank > 0)
    return ShieldDecision(action_index(-MAX_BRAKE_MPS), overridden=True)
