"""The paper's training schedule of episodes: command, stop injections, traffic and seed.

In even-numbered episodes the primary command (fast or comfort) is interleaved with stop
commands at random intervals; in odd-numbered episodes it holds for the whole episode. The
traffic level and the simulation seed vary per episode. Every plan is a pure function of
the run seed and the episode index, so a resumed run replays the same episodes. The rules
are those of :mod:`explaindrive.env.curriculum`, which the Gymnasium wrappers of
:mod:`explaindrive.env.wrappers` apply for any learner.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from explaindrive.agent.config import TrainConfig
from explaindrive.commands import Command
from explaindrive.env.curriculum import draw_level, draw_seed, stop_schedule, stops_injected

__all__ = ["EpisodePlan", "plan_episode", "stop_schedule"]


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


def plan_episode(config: TrainConfig, index: int) -> EpisodePlan:
    """The plan of episode ``index`` (0-based; episode 0 is even) of a run."""
    if index < 0:
        raise ValueError(f"episode index must be >= 0, got {index}")
    rng = np.random.default_rng([config.seed, index])
    seed = draw_seed(rng, config.seed_pool)
    level = draw_level(rng, config.traffic_levels)
    primary = config.command
    schedule: tuple[tuple[float, str], ...] = ()
    if stops_injected(index):
        schedule = stop_schedule(
            rng, primary, config.stop_gap_s, config.stop_duration_s, config.schedule_horizon_s
        )
    noise = (0.0, 0.0)
    if config.obs_noise_max != (0.0, 0.0):
        # a generator of its own: the plans of runs without noise stay as they were
        # the fourth draw only decides the speeds' share apart: the first three are as before
        u = np.random.default_rng([config.seed, index, 11]).uniform(size=4)
        speed_share = config.speed_noisy_share
        noisy_speeds = u[2] < config.noisy_share if speed_share is None else u[3] < speed_share
        noise = (
            round(float(u[0]) * config.obs_noise_max[0], 3) if u[2] < config.noisy_share else 0.0,
            round(float(u[1]) * config.obs_noise_max[1], 3) if noisy_speeds else 0.0,
        )
    return EpisodePlan(index, seed, level, primary, schedule, noise)
