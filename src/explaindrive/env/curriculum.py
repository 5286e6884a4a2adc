"""The rules of the training curriculum: stop commands injected at random times, a traffic
level and a simulation seed per episode.

The trainer's episode plans (:func:`explaindrive.agent.schedule.plan_episode`) and the
Gymnasium wrappers any learner can use (:mod:`explaindrive.env.wrappers`) both draw with
these functions.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from explaindrive.commands import Command
from explaindrive.sim.scenario.layout import SEED_LIMIT

SEED_POOL_BASE = 100_000  # training seeds from a pool start here, clear of evaluation seeds
STOP_GAP_S: tuple[float, float] = (15.0, 60.0)
"""[s] range of the random time before each injected stop command."""
STOP_DURATION_S: tuple[float, float] = (5.0, 15.0)
"""[s] range of the random duration of each injected stop command."""
SCHEDULE_HORIZON_S = 900.0
"""[s] stop commands are scheduled up to this simulated time."""
STOP_EPISODES_EVERY = 2
"""Stops are injected in every such episode, counted from episode 0 (the even ones)."""


def stops_injected(index: int, every: int = STOP_EPISODES_EVERY) -> bool:
    """Whether episode ``index`` (0-based) gets injected stop commands."""
    return index % every == 0


def stop_schedule(
    rng: np.random.Generator,
    primary: Command,
    gap_s: tuple[float, float],
    duration_s: tuple[float, float],
    horizon_s: float,
) -> tuple[tuple[float, str], ...]:
    """Alternate ``primary`` with stop commands at random times up to ``horizon_s``.

    Each cycle waits ``U(gap_s)`` seconds of the primary command, then holds stop for
    ``U(duration_s)`` seconds. Times are rounded to whole seconds (the decision step).
    """
    switches: list[tuple[float, str]] = []
    t = 0.0
    while True:
        t += max(1.0, round(float(rng.uniform(*gap_s))))
        if t >= horizon_s:
            break
        switches.append((t, Command.STOP.label))
        t += max(1.0, round(float(rng.uniform(*duration_s))))
        switches.append((t, primary.label))
    return tuple(switches)


def draw_seed(rng: np.random.Generator, pool: int | None) -> int:
    """An episode's simulation seed: any valid seed, or one of ``pool`` seeds from
    :data:`SEED_POOL_BASE` on (their warm-up states are cached and reused)."""
    if pool is None:
        return int(rng.integers(0, SEED_LIMIT - 1))
    return SEED_POOL_BASE + int(rng.integers(pool))


def draw_level(rng: np.random.Generator, levels: Sequence[float]) -> float:
    """An episode's traffic level, uniformly from ``levels``."""
    return float(levels[int(rng.integers(len(levels)))])
