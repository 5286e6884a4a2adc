"""Scripted drivers: a cautious rule-based driver and reckless ones for testing the metrics."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import SPEED_CHANGES_MPS, action_index

CAUTIOUS_PLAN_DECEL_MPS2 = 2.5  # [m/s^2] planned braking of the cautious driver
STANDSTILL_GAP_M = 4.0  # [m] gap it keeps to a stopped leader


class CautiousDriver:
    """Drives at the speed from which it could still stop behind the leader.

    Target speed = min(v_lim, sqrt(2 b (d_lead - s0))); under STOP it brakes at
    -3 m/s per step. Works on raw (not normalised) observations.
    """

    def __call__(self, obs: NDArray[np.floating]) -> int:
        """Action index for a raw observation."""
        v = float(obs[S.V_EGO])
        if round(float(obs[S.CMD])) == Command.STOP:
            return action_index(-min(3, math.ceil(v)))
        room = max(0.0, float(obs[S.D_LEAD]) - STANDSTILL_GAP_M)
        target = min(float(obs[S.V_LIM]), math.sqrt(2.0 * CAUTIOUS_PLAN_DECEL_MPS2 * room))
        change = int(np.clip(math.floor(target - v), SPEED_CHANGES_MPS[0], SPEED_CHANGES_MPS[-1]))
        return action_index(change)


class AlwaysAccelerate:
    """Adds +3 m/s every step, ignoring everything (it must collide or break rules)."""

    def __call__(self, obs: NDArray[np.floating]) -> int:
        """Action index of +3 m/s."""
        return action_index(3)


class ConstantSpeed:
    """Accelerates to a fixed speed and holds it, ignoring leaders and lights."""

    def __init__(self, speed_mps: int) -> None:
        self.speed_mps = speed_mps

    def __call__(self, obs: NDArray[np.floating]) -> int:
        """Action index towards the fixed speed."""
        diff = int(np.clip(self.speed_mps - round(float(obs[S.V_EGO])), -3, 3))
        return action_index(diff)
