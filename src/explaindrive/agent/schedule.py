"""The paper's training schedule of episodes: command, stop injections, traffic and seed.

In even-numbered episodes the primary command (fast or comfort) is interleaved with stop
commands at random intervals; in odd-numbered episodes it holds for the whole episode. The
traffic level and the simulation seed vary per episode. Every plan is a pure function of
the run seed and the episode index, so a resumed run replays the same episodes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from explaindrive.agent.config import SEED_POOL_BASE, TrainConfig
from explaindrive.commands import Command
from explaindrive.sim.scenario.layout import SEED_LIMIT


@dataclass(frozen=True)
class EpisodePlan:
    """How one training episode is set up."""

    index: int
    seed: int
    traffic_level: float
    command: Command
    command_schedule: tuple[tuple[float, str], ...]  # (time [s], command label) switches
    obs_noise: tuple[float, float] = (0.0, 0.0)  # (sd_m, sd_mps) of the observation noise

    @property
    def has_stops(self) -> bool:
        """Whether stop commands are injected in this episode."""
        return bool(self.command_schedule)

    def reset_options(self) -> dict[str, Any]:
        """The ``options`` of ``env.reset`` for this episode."""
        options: dict[str, Any] = {
            "command": self.command.label,
            "traffic_level": self.traffic_level,
            "command_schedule": [list(s) for s in self.command_schedule],
        }
        if self.obs_noise != (0.0, 0.0):
            options["obs_noise"] = list(self.obs_noise)
        return options


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


def plan_episode(config: TrainConfig, index: int) -> EpisodePlan:
    """The plan of episode ``index`` (0-based; episode 0 is even) of a run."""
    if index < 0:
        raise ValueError(f"episode index must be >= 0, got {index}")
    rng = np.random.default_rng([config.seed, index])
    if config.seed_pool is None:
        seed = int(rng.integers(0, SEED_LIMIT - 1))
    else:
        seed = SEED_POOL_BASE + int(rng.integers(config.seed_pool))
    level = float(config.traffic_levels[int(rng.integers(len(config.traffic_levels)))])
    primary = config.command
    schedule: tuple[tuple[float, str], ...] = ()
    if index % 2 == 0:
        schedule = stop_schedule(
            rng, primary, config.stop_gap_s, config.stop_duration_s, config.schedule_horizon_s
        )
    noise = (0.0, 0.0)
    if config.obs_noise_max != (0.0, 0.0):
        # a generator of its own: the plans of runs without noise stay as they were
        u = np.random.default_rng([config.seed, index, 11]).uniform(size=3)
        if u[2] < config.noisy_share:
            noise = (
                round(float(u[0]) * config.obs_noise_max[0], 3),
                round(float(u[1]) * config.obs_noise_max[1], 3),
            )
    return EpisodePlan(index, seed, level, primary, schedule, noise)
