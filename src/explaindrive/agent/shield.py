"""A kinematic safety shield: the best-valued action that keeps a stopping option.

Which actions are safe is the rule of :mod:`explaindrive.env.safety` (the environment
reports the same mask); it is re-exported here, and the scalar helpers index it. At run
time (:func:`shield`) braking in a yellow light's dilemma zone is unsafe; the training mask
leaves it allowed. Under STOP the shield also keeps the stop within its latency bound
(ceil(v/3) + 2 steps from the command); the training mask asks instead that every step
under STOP brings the standstill one hardest-braking step closer, which keeps that bound
without knowing when the command came. With the speed limiter (``speed_limiter``, the
``passenger`` preset's) actions are judged by the speed the limiter lands them on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from explaindrive.env import state as S
from explaindrive.env.actions import MAX_BRAKE_MPS, SPEED_CHANGES_MPS
from explaindrive.env.safety import (
    HARDEST_BRAKE,
    LEADER_BRAKE_MPS,
    TRUE_VIRTUAL_TOL_M,
    limit_mask,
    runtime_mask,
    safe_action_mask,
    steps_to_stop,
    training_mask,
)

__all__ = [
    "HARDEST_BRAKE",
    "LEADER_BRAKE_MPS",
    "TRUE_VIRTUAL_TOL_M",
    "ShieldDecision",
    "is_safe",
    "limit_mask",
    "runtime_mask",
    "safe_action_mask",
    "shield",
    "steps_to_stop",
    "stop_in_time",
    "training_mask",
]


@dataclass(frozen=True, slots=True)
class ShieldDecision:
    """The shielded action and whether the shield overrode the policy."""

    action: int
    overridden: bool


def is_safe(obs: NDArray[np.floating], action: int, speed_limiter: bool = False) -> bool:
    """Whether ``action`` keeps a stopping option and respects the posted limit
    (``speed_limiter``: through the speed limiter)."""
    return bool(safe_action_mask(obs, speed_limiter=speed_limiter)[action])


def stop_in_time(speed_mps: float, action: int, steps_left: int) -> bool:
    """Whether, after ``action``, braking hardest still reaches 0 m/s within ``steps_left``
    steps (this one included): the STOP latency guarantee."""
    v_new = max(0.0, speed_mps + SPEED_CHANGES_MPS[action])
    return 1 + math.ceil(v_new / MAX_BRAKE_MPS) <= steps_left


def shield(
    obs: NDArray[np.floating],
    q_values: Sequence[float] | NDArray[np.floating],
    stop_steps_left: int | None = None,
    speed_limiter: bool = False,
) -> ShieldDecision:
    """The best-valued safe action for a raw observation.

    Args:
        obs: raw observation.
        q_values: the policy's Q-values, one per action.
        stop_steps_left: under STOP, the steps left to reach a standstill; actions that
            would miss it are not allowed.
        speed_limiter: judge the actions through the speed limiter.
    """
    order = np.argsort(-np.asarray(q_values, dtype=np.float64), kind="stable")
    mask = safe_action_mask(obs, speed_limiter=speed_limiter)
    v = float(obs[S.V_EGO])
    for rank, a in enumerate(order):
        late = (
            stop_steps_left is not None and v > 0 and not stop_in_time(v, int(a), stop_steps_left)
        )
        if not late and mask[a]:
            return ShieldDecision(int(a), overridden=rank > 0)
    return ShieldDecision(HARDEST_BRAKE, overridden=True)
