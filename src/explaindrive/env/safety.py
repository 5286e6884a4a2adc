"""The safety rule of the run-time shield and of masked learning: which of the 7 actions keep
a stopping option.

An action is safe when, after it, the ego could still stop braking at -3 m/s per step:

- behind its real leader, even if that leader brakes at 9 m/s^2 (SUMO's emergency
  deceleration), with a 2 m margin;
- before a red or yellow light and before an occupied crossing (the virtual leaders);
- without exceeding the posted limit (above it, only the hardest braking is safe).

Standing still after the step is safe with respect to every stop line and leader.

A yellow light that even the hardest braking cannot stop for is the dilemma zone: the
ego goes on without slowing down, since braking would only leave it on the junction at
red. :func:`runtime_mask` (the shield's rule) forbids braking there; :func:`training_mask`
(with ``dilemma_braking=True``) leaves it allowed, so that learning is not taught to forbid
it. Under STOP both ask that every step brings the standstill one hardest-braking step
closer.

Every rule is written once, vectorised over a batch of raw observations
(:func:`safe_action_mask`). The environment reports :func:`runtime_mask` of the true state
as ``info["action_mask"]``; :mod:`explaindrive.agent.shield` builds the run-time shield on
these rules.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import (
    MAX_BRAKE_MPS,
    SPEED_CHANGES_MPS,
    action_index,
    braking_distances,
    stopping_needs,
)

LEADER_BRAKE_MPS = 9.0  # [m/s per step] how hard a real leader may brake (SUMO emergency decel)
VIRTUAL_TOL_M = 0.5  # [m] a leader this close to a stop line is the virtual leader
HARDEST_BRAKE = action_index(-MAX_BRAKE_MPS)
_CHANGES = np.asarray(SPEED_CHANGES_MPS, dtype=np.float64)


def steps_to_stop(speed_mps: NDArray[np.floating] | float) -> NDArray[np.float64]:
    """Steps of hardest braking from ``speed_mps`` to a standstill: ceil(v / 3)."""
    v = np.maximum(np.asarray(speed_mps, dtype=np.float64), 0.0)
    return np.ceil(v / MAX_BRAKE_MPS - 1e-6)


def safe_action_mask(
    obs: NDArray[np.floating], dilemma_braking: bool = False, stop_progress: bool = False
) -> NDArray[np.bool_]:
    """Which of the 7 actions are safe in each raw observation.

    Args:
        obs: raw observations, shape ``(B, 8)`` (or one of shape ``(8,)``).
        dilemma_braking: allow slowing down in the yellow-light dilemma zone (training).
        stop_progress: under STOP (``cmd = 2``), allow only actions after which the
            hardest braking needs one step fewer to a standstill (and, at a standstill,
            only staying there); in the dilemma zone keeping the speed is allowed too, to
            clear the junction before stopping.

    Returns:
        Boolean mask of shape ``(B, 7)`` (``(7,)`` for one observation). A row may be all
        false: then no action keeps a stopping option (see :func:`training_mask`).
    """
    x = np.asarray(obs, dtype=np.float64)
    single = x.ndim == 1
    x = x.reshape(-1, S.STATE_DIM)
    v = x[:, S.V_EGO : S.V_EGO + 1]  # (B, 1)
    v_new = np.maximum(v + _CHANGES, 0.0)  # (B, 7)
    need = stopping_needs(v_new)

    safe = _within_limit(x, v_new)

    d_cross = x[:, S.D_CROSS : S.D_CROSS + 1]
    safe &= ~((d_cross < S.SENSOR_RANGE_M) & (need > d_cross))

    d_tl = x[:, S.D_TL : S.D_TL + 1]
    tls = np.rint(x[:, S.TLS : S.TLS + 1])
    light = (d_tl < S.SENSOR_RANGE_M) & (tls != 0)
    # the hardest braking's need is what stopping from now on needs (``stops_before``)
    must_go = light & (tls == 1) & ~(need[:, HARDEST_BRAKE : HARDEST_BRAKE + 1] <= d_tl)
    safe &= ~(light & ~must_go & (need > d_tl))
    if not dilemma_braking:
        safe &= ~(must_go & (v_new < v))

    gap = x[:, S.D_LEAD : S.D_LEAD + 1]
    virtual = ((tls != 0) & (np.abs(gap - d_tl) <= VIRTUAL_TOL_M)) | (
        np.abs(gap - d_cross) <= VIRTUAL_TOL_M
    )
    real = (gap < S.SENSOR_RANGE_M) & ~virtual
    leader_v = np.maximum(v - x[:, S.DV : S.DV + 1], 0.0)
    safe &= ~(real & (gap + braking_distances(leader_v, LEADER_BRAKE_MPS) < need))

    if stop_progress:
        stopping = np.rint(x[:, S.CMD : S.CMD + 1]) == int(Command.STOP)
        closer = (steps_to_stop(v_new) < steps_to_stop(v)) | (v_new <= 0.0)
        clearing = must_go & (v_new == v)  # in the dilemma zone: clear the junction first
        safe &= ~(stopping & ~closer & ~clearing)
    return safe[0] if single else safe


def _within_limit(
    x: NDArray[np.float64], v_new: NDArray[np.float64] | None = None
) -> NDArray[np.bool_]:
    """Rows ``(B, 8)`` -> ``(B, 7)``: the actions that keep within the posted limit; above
    it, only the hardest braking. ``v_new``: the speeds after each action, if computed."""
    v = x[:, S.V_EGO : S.V_EGO + 1]
    if v_new is None:
        v_new = np.maximum(v + _CHANGES, 0.0)
    return ~((v_new > x[:, S.V_LIM : S.V_LIM + 1]) & (v_new > v - MAX_BRAKE_MPS + 1e-9))


def limit_mask(obs: NDArray[np.floating]) -> NDArray[np.bool_]:
    """The posted-limit rule of :func:`safe_action_mask` alone, for raw observations of shape
    ``(B, 8)`` (or ``(8,)``)."""
    x = np.asarray(obs, dtype=np.float64)
    mask = _within_limit(x.reshape(-1, S.STATE_DIM))
    return mask[0] if x.ndim == 1 else mask


def _with_fallback(mask: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Rows that allow nothing allow the hardest braking (what the shield does there)."""
    rows = mask.reshape(-1, len(SPEED_CHANGES_MPS))
    rows[~rows.any(axis=1), HARDEST_BRAKE] = True
    return mask


def training_mask(obs: NDArray[np.floating], dilemma_braking: bool = True) -> NDArray[np.bool_]:
    """The safety mask learning uses: dilemma braking allowed unless ``dilemma_braking`` is
    false, STOP must make progress, and the hardest braking where nothing is safe (every row
    allows an action)."""
    return _with_fallback(
        safe_action_mask(obs, dilemma_braking=dilemma_braking, stop_progress=True)
    )


def runtime_mask(obs: NDArray[np.floating]) -> NDArray[np.bool_]:
    """The actions the run-time shield keeps (dilemma braking forbidden), with STOP's
    progress rule standing in for its latency bound: a greedy action outside this mask is
    one the shield would override."""
    return _with_fallback(safe_action_mask(obs, stop_progress=True))
