"""The safety rule of the run-time shield and of masked learning: which of the 7 actions keep
a stopping option.

An action is safe when, after it, the ego could still stop braking at -3 m/s per step:

- behind its real leader, even if that leader brakes at 9 m/s^2 (SUMO's emergency
  deceleration), with a 2 m margin;
- before a red or yellow light and before an occupied crossing (the virtual leaders);
- without exceeding the posted limit (above it, only the hardest braking is safe).

With the speed limiter (``speed_limiter=True``, the ``passenger`` preset's;
:func:`~explaindrive.env.actions.limited_speed`) an action is judged by the speed it lands
on: a rise that would pass the limit lands on it, so it does not exceed the limit, and above
the limit keeping or raising the speed slows the car by 1 m/s, down to the limit.

Standing still after the step is safe with respect to every stop line and leader.

A yellow light that even the hardest braking cannot stop for is the dilemma zone: the
ego goes on without slowing down, since braking would only leave it on the junction at
red. :func:`runtime_mask` (the shield's rule) forbids braking there; :func:`training_mask`
(with ``dilemma_braking=True``) leaves it allowed, so that learning is not taught to forbid
it. Under STOP both ask that every step brings the standstill one hardest-braking step
closer.

The rule is written vectorised over a batch of raw observations (:func:`_unsafe`, what
learning's targets use) and, for the one observation the environment and the shield check
every step, in plain Python (:func:`_unsafe_one`: numpy's per-call overhead is most of the
cost of one row), with what the actions do at its speed kept per speed.
tests/env/test_safety.py holds the two to the same answer on random and edge-case
observations. The environment reports :func:`runtime_mask` of the true state as
``info["action_mask"]``; :mod:`explaindrive.agent.shield` builds the run-time shield on
these rules.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import (
    LIMITER_COAST_MPS,
    MAX_BRAKE_MPS,
    SPEED_CHANGES_MPS,
    SPEEDS_KEPT,
    action_index,
    braking_distances,
    least_stopping_needs,
    stopping_needs,
)

LEADER_BRAKE_MPS = 9.0  # [m/s per step] how hard a real leader may brake (SUMO emergency decel)
TRUE_VIRTUAL_TOL_M = 0.5  # [m] in the true state: a leader this close to a stop line is virtual
HARDEST_BRAKE = action_index(-MAX_BRAKE_MPS)
_CHANGES = np.asarray(SPEED_CHANGES_MPS, dtype=np.float64)


def steps_to_stop(speed_mps: NDArray[np.floating] | float) -> NDArray[np.float64]:
    """Steps of hardest braking from ``speed_mps`` to a standstill: ceil(v / 3)."""
    v = np.maximum(np.asarray(speed_mps, dtype=np.float64), 0.0)
    return np.ceil(v / MAX_BRAKE_MPS - 1e-6)


class ActionOutcomes(NamedTuple):
    """What each of the 7 actions does to cars at given speeds: everything of the rule that
    depends on the speed alone. Arrays of shape ``(B, 7)`` (``least_need``: ``(B, 1)``)
    for speeds of shape ``(B, 1)``; of shape ``(7,)`` (``least_need``: 0-d) for one speed."""

    v_new: NDArray[np.float64]
    """The speed after the action."""
    need: NDArray[np.float64]
    """What standing still after it needs ahead (:func:`stopping_needs`)."""
    least_need: NDArray[np.float64]
    """What stopping from now on needs: the hardest braking's need (``stops_before``)."""
    slows: NDArray[np.bool_]
    """The action lowers the speed."""
    keeps: NDArray[np.bool_]
    """The action keeps the speed."""
    closer: NDArray[np.bool_]
    """After it the hardest braking needs a step fewer to a standstill, or none."""
    eases: NDArray[np.bool_]
    """It brakes less than the hardest braking."""


def action_outcomes(
    speed_mps: NDArray[np.float64] | float, limit_mps: NDArray[np.float64] | float = math.inf
) -> ActionOutcomes:
    """The :class:`ActionOutcomes` of speeds of shape ``(B, 1)``, or of one speed, through
    the speed limiter at ``limit_mps`` (:func:`~explaindrive.env.actions.limited_speed`;
    ``inf``: no limiter)."""
    v = speed_mps
    v_new = np.maximum(v + _CHANGES, 0.0)
    limited = (_CHANGES >= 0) & (v_new > limit_mps)
    v_new = np.where(limited, np.maximum(limit_mps, v - LIMITER_COAST_MPS), v_new)
    return ActionOutcomes(
        v_new=v_new,
        need=stopping_needs(v_new),
        least_need=least_stopping_needs(np.asarray(v)),
        slows=v_new < v,
        keeps=v_new == v,
        closer=(steps_to_stop(v_new) < steps_to_stop(v)) | (v_new <= 0.0),
        eases=v_new > v - MAX_BRAKE_MPS + 1e-9,
    )


def safe_action_mask(
    obs: NDArray[np.floating],
    dilemma_braking: bool = False,
    stop_progress: bool = False,
    speed_limiter: bool = False,
) -> NDArray[np.bool_]:
    """Which of the 7 actions are safe in each raw observation.

    Args:
        obs: raw observations, shape ``(B, 8)`` (or one of shape ``(8,)``).
        dilemma_braking: allow slowing down in the yellow-light dilemma zone (training).
        stop_progress: under STOP (``cmd = 2``), allow only actions after which the
            hardest braking needs one step fewer to a standstill (and, at a standstill,
            only staying there); in the dilemma zone keeping the speed is allowed too, to
            clear the junction before stopping.
        speed_limiter: judge each action by the speed the speed limiter lands it on.

    Returns:
        Boolean mask of shape ``(B, 7)`` (``(7,)`` for one observation). A row may be all
        false: then no action keeps a stopping option (see :func:`training_mask`).
    """
    return _mask(obs, dilemma_braking, stop_progress, fallback=False, limiter=speed_limiter)


def _mask(
    obs: NDArray[np.floating],
    dilemma_braking: bool,
    stop_progress: bool,
    fallback: bool,
    limiter: bool = False,
) -> NDArray[np.bool_]:
    """:func:`safe_action_mask`; with ``fallback``, rows that allow nothing allow the
    hardest braking (what the shield does there); ``limiter``: the speed limiter is on."""
    x = np.asarray(obs)
    if x.ndim == 1:  # one observation: the rule in plain Python, one numpy call
        unsafe = _unsafe_one(x.tolist(), dilemma_braking, stop_progress, limiter)
        safe = [not u for u in unsafe]
        if fallback and not any(safe):
            safe[HARDEST_BRAKE] = True
        return np.array(safe, dtype=np.bool_)
    columns, outcomes = _columns(x.astype(np.float64, copy=False), limiter)
    mask = ~_unsafe(columns, outcomes, dilemma_braking, stop_progress)
    if fallback:
        rows = mask.reshape(-1, len(SPEED_CHANGES_MPS))
        rows[~rows.any(axis=1), HARDEST_BRAKE] = True
    return mask


def _columns(
    x: NDArray[np.float64], limiter: bool = False
) -> tuple[tuple[Any, ...], ActionOutcomes]:
    """The 8 components of raw observations ``(B, 8)``, each a column ``(B, 1)``, and the
    :class:`ActionOutcomes` of their speeds (through the speed limiter with ``limiter``)."""
    rows = x.reshape(-1, S.STATE_DIM)
    v = rows[:, S.V_EGO : S.V_EGO + 1]
    limit = rows[:, S.V_LIM : S.V_LIM + 1] if limiter else math.inf
    return tuple(rows.T[:, :, None]), action_outcomes(v, limit)


def _unsafe(
    columns: tuple[Any, ...], out: ActionOutcomes, dilemma_braking: bool, stop_progress: bool
) -> NDArray[np.bool_]:
    """The rule of :func:`safe_action_mask` over a batch: which actions are unsafe.

    Args:
        columns: the 8 components of the observations, each of shape ``(B, 1)``.
        out: the :class:`ActionOutcomes` of their speeds.
        dilemma_braking, stop_progress: as in :func:`safe_action_mask`.
    """
    cmd, v, v_lim, gap, dv, d_tl, tls, d_cross = columns
    need = out.need
    unsafe = _over_limit(v_lim, out)
    # Each rule below applies only where its condition holds; where it holds for no
    # observation the rule is skipped.
    crossing = d_cross < S.SENSOR_RANGE_M
    if _anywhere(crossing):
        unsafe |= crossing & (need > d_cross)

    tls = np.rint(tls)
    signal = tls != 0
    light = (d_tl < S.SENSOR_RANGE_M) & signal
    must_go = light  # no light in range: nothing must go
    if _anywhere(light):
        must_go = light & (tls == 1) & ~(out.least_need <= d_tl)
        unsafe |= light & ~must_go & (need > d_tl)
        if not dilemma_braking:
            unsafe |= must_go & out.slows

    virtual = (signal & (np.abs(gap - d_tl) <= TRUE_VIRTUAL_TOL_M)) | (
        np.abs(gap - d_cross) <= TRUE_VIRTUAL_TOL_M
    )
    real = (gap < S.SENSOR_RANGE_M) & ~virtual
    if _anywhere(real):
        leader_v = np.maximum(v - dv, 0.0)
        unsafe |= real & (gap + braking_distances(leader_v, LEADER_BRAKE_MPS) < need)

    if stop_progress:
        stopping = np.rint(cmd) == int(Command.STOP)
        if _anywhere(stopping):
            clearing = must_go & out.keeps  # in the dilemma zone: clear the junction first
            unsafe |= stopping & ~(out.closer | clearing)
    return unsafe


def _anywhere(condition: NDArray[np.bool_]) -> bool:
    """Whether ``condition`` (a boolean column) holds for any observation."""
    return bool(condition.any())


def _over_limit(v_lim: Any, out: ActionOutcomes) -> NDArray[np.bool_]:
    """The actions that exceed the posted limit ``v_lim`` (a column); above it, all but the
    hardest braking. ``out``: the :class:`ActionOutcomes` of the speeds."""
    return (out.v_new > v_lim) & out.eases


class _Action(NamedTuple):
    """:class:`ActionOutcomes` of one action at one speed, as Python values."""

    v_new: float
    need: float
    slows: bool
    keeps: bool
    closer: bool
    eases: bool

    def over(self, v_lim: float) -> bool:
        """It exceeds the posted limit (:func:`_over_limit`)."""
        return self.v_new > v_lim and self.eases


@lru_cache(maxsize=SPEEDS_KEPT)
def _actions_at(speed_mps: float, limit_mps: float = math.inf) -> tuple[tuple[_Action, ...], float]:
    """The 7 actions' outcomes at one speed (through the speed limiter at ``limit_mps``) and
    ``least_need``, kept per speed (the speeds of an episode repeat)."""
    o = action_outcomes(speed_mps, limit_mps)
    columns = (o.v_new, o.need, o.slows, o.keeps, o.closer, o.eases)
    actions = tuple(_Action(*row) for row in zip(*(c.tolist() for c in columns), strict=True))
    return actions, float(o.least_need)


def _code(value: float) -> float:
    """A light or command code rounded as :func:`numpy.rint` does (NaN and inf kept)."""
    return round(value) if math.isfinite(value) else value


def _unsafe_one(
    values: list[float], dilemma_braking: bool, stop_progress: bool, limiter: bool = False
) -> list[bool]:
    """The rule of :func:`_unsafe` for one observation's 8 components: which actions are
    unsafe. Standing still after an action needs its ``need`` ahead: the room up to the
    nearest busy crossing, light to stop for and point where the real leader could stop.
    ``limiter``: the speed limiter is on."""
    cmd, v, v_lim, gap, dv, d_tl, tls, d_cross = values
    actions, least_need = _actions_at(v, v_lim if limiter else math.inf)
    room = d_cross if d_cross < S.SENSOR_RANGE_M else math.inf
    tls = _code(tls)
    signal = tls != 0
    light = d_tl < S.SENSOR_RANGE_M and signal
    must_go = light and tls == 1 and not least_need <= d_tl
    if light and not must_go:
        room = min(room, d_tl)
    tol = TRUE_VIRTUAL_TOL_M
    virtual = (signal and abs(gap - d_tl) <= tol) or abs(gap - d_cross) <= tol
    if gap < S.SENSOR_RANGE_M and not virtual:
        leader_v = max(v - dv, 0.0)
        room = min(room, gap + float(braking_distances(leader_v, LEADER_BRAKE_MPS)))
    no_slowing = must_go and not dilemma_braking
    stopping = stop_progress and _code(cmd) == int(Command.STOP)
    return [
        a.over(v_lim)
        or a.need > room
        or (no_slowing and a.slows)
        or (stopping and not (a.closer or (must_go and a.keeps)))
        for a in actions
    ]


def limit_mask(obs: NDArray[np.floating], speed_limiter: bool = False) -> NDArray[np.bool_]:
    """The posted-limit rule of :func:`safe_action_mask` alone, for raw observations of shape
    ``(B, 8)`` (or ``(8,)``); ``speed_limiter``: through the speed limiter."""
    x = np.asarray(obs)
    if x.ndim == 1:
        values = x.tolist()
        v, v_lim = values[S.V_EGO], values[S.V_LIM]
        actions, _ = _actions_at(v, v_lim if speed_limiter else math.inf)
        return np.array([not a.over(v_lim) for a in actions], dtype=np.bool_)
    columns, outcomes = _columns(x.astype(np.float64, copy=False), speed_limiter)
    return ~_over_limit(columns[S.V_LIM], outcomes)


def training_mask(
    obs: NDArray[np.floating], dilemma_braking: bool = True, speed_limiter: bool = False
) -> NDArray[np.bool_]:
    """The safety mask learning uses: dilemma braking allowed unless ``dilemma_braking`` is
    false, STOP must make progress, and the hardest braking where nothing is safe (every row
    allows an action); ``speed_limiter``: through the speed limiter."""
    return _mask(obs, dilemma_braking, stop_progress=True, fallback=True, limiter=speed_limiter)


def runtime_mask(obs: NDArray[np.floating], speed_limiter: bool = False) -> NDArray[np.bool_]:
    """The actions the run-time shield keeps (dilemma braking forbidden), with STOP's
    progress rule standing in for its latency bound: a greedy action outside this mask is
    one the shield would override. ``speed_limiter``: through the speed limiter."""
    return _mask(
        obs, dilemma_braking=False, stop_progress=True, fallback=True, limiter=speed_limiter
    )
