"""The training curriculum as Gymnasium wrappers that any learner can use.

Each wrapper fills one reset option of :class:`~explaindrive.env.urban_drive.UrbanDriveEnv`
per episode, with the rules the project's trainer uses (:mod:`explaindrive.env.curriculum`):

- :class:`CommandSchedule`: the primary command of each episode;
- :class:`StopInjection`: stop commands at random times in every other episode;
- :class:`RandomTraffic`: a traffic level per episode;
- :class:`SeedPool`: the simulation seed of each episode from a pool of cached warm-ups.

Options given to ``reset`` explicitly are kept. A wrapper draws from its own generator,
seeded by the first ``reset(seed=...)`` (a fresh one without a seed), so a seeded run
gives the same episodes. ``reset`` options travel from the outermost wrapper inwards, so
put :class:`CommandSchedule` outside :class:`StopInjection` (the stops return to the
episode's command)::

    env = CommandSchedule(StopInjection(RandomTraffic(gym.make(ENV_ID))), ("fast", "comfort"))

and :class:`SeedPool`, which passes a seed every episode, directly around the env.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np

from explaindrive.commands import Command
from explaindrive.env.curriculum import (
    SCHEDULE_HORIZON_S,
    SEED_POOL_BASE,
    STOP_DURATION_S,
    STOP_EPISODES_EVERY,
    STOP_GAP_S,
    draw_level,
    draw_seed,
    stop_schedule,
    stops_injected,
)
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS, validate_traffic_level

Obs = Any
Act = Any


class _EpisodeOptions(gym.Wrapper[Obs, Act, Obs, Act]):
    """A wrapper that sets reset options of each episode from its own random generator.

    Args:
        env: the environment to wrap.
        salt: mixed into the seed, so that wrappers seeded alike draw differently.
    """

    def __init__(self, env: gym.Env[Obs, Act], salt: int) -> None:
        super().__init__(env)
        self._salt = salt
        self._rng: np.random.Generator | None = None
        self.episode = 0
        """Episodes started since the wrapper was made or last seeded (0 before the first)."""

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        """Reset the wrapped env with this episode's options filled in."""
        if seed is not None:
            self._rng = np.random.default_rng([seed, self._salt])
            self.episode = 0
        elif self._rng is None:
            self._rng = np.random.default_rng()
        opts = dict(options or {})
        seed = self._fill(opts, self._rng, seed)
        self.episode += 1
        return self.env.reset(seed=seed, options=opts)

    def _fill(
        self, options: dict[str, Any], rng: np.random.Generator, seed: int | None
    ) -> int | None:
        """Add this wrapper's options for episode ``self.episode``; returns the seed."""
        raise NotImplementedError


class CommandSchedule(_EpisodeOptions):
    """The primary command of each episode, drawn uniformly from ``commands``.

    Args:
        env: the environment to wrap.
        commands: the commands to draw from (one: every episode runs under it).

    Raises:
        ValueError: for an empty list or an unknown command.
    """

    def __init__(
        self, env: gym.Env[Obs, Act], commands: Sequence[str | Command] = ("fast",)
    ) -> None:
        super().__init__(env, salt=101)
        if isinstance(commands, str | Command):
            commands = (commands,)
        if not commands:
            raise ValueError("CommandSchedule needs at least one command")
        self.commands = tuple(Command.parse(c) for c in commands)

    def _fill(
        self, options: dict[str, Any], rng: np.random.Generator, seed: int | None
    ) -> int | None:
        if "command" not in options:
            options["command"] = self.commands[int(rng.integers(len(self.commands)))].label
        return seed


class StopInjection(_EpisodeOptions):
    """Stop commands at random times in every ``every``-th episode (the first included):
    ``U(gap_s)`` seconds under the episode's command, then ``U(duration_s)`` seconds of stop,
    up to ``horizon_s``, as the trainer does.

    Args:
        env: the environment to wrap.
        gap_s: [s] range of the time before each stop.
        duration_s: [s] range of each stop's duration.
        horizon_s: [s] stops are scheduled up to this time.
        every: stops are injected in every such episode.

    Raises:
        ValueError: for an empty or negative range, or ``every`` < 1.
    """

    def __init__(
        self,
        env: gym.Env[Obs, Act],
        gap_s: tuple[float, float] = STOP_GAP_S,
        duration_s: tuple[float, float] = STOP_DURATION_S,
        horizon_s: float = SCHEDULE_HORIZON_S,
        every: int = STOP_EPISODES_EVERY,
    ) -> None:
        super().__init__(env, salt=102)
        for name, (lo, hi) in (("gap_s", gap_s), ("duration_s", duration_s)):
            if not 0.0 < lo <= hi:
                raise ValueError(f"StopInjection {name} must be (min, max) with 0 < min <= max")
        if every < 1:
            raise ValueError(f"StopInjection every must be >= 1, got {every}")
        self.gap_s, self.duration_s = gap_s, duration_s
        self.horizon_s, self.every = horizon_s, every

    def _fill(
        self, options: dict[str, Any], rng: np.random.Generator, seed: int | None
    ) -> int | None:
        if "command_schedule" not in options and stops_injected(self.episode, self.every):
            primary = Command.parse(options.get("command", Command.FAST))
            switches = stop_schedule(rng, primary, self.gap_s, self.duration_s, self.horizon_s)
            options["command_schedule"] = [list(s) for s in switches]
        return seed


class RandomTraffic(_EpisodeOptions):
    """A traffic level per episode, uniformly from ``levels``.

    Args:
        env: the environment to wrap.
        levels: the levels to draw from (the trainer's default: 0.5 to 1.5).

    Raises:
        ValueError: for an empty list or a level out of range.
    """

    def __init__(
        self, env: gym.Env[Obs, Act], levels: Sequence[SupportsFloat] = TRAFFIC_LEVELS
    ) -> None:
        super().__init__(env, salt=103)
        if not levels:
            raise ValueError("RandomTraffic needs at least one traffic level")
        self.levels = tuple(validate_traffic_level(float(x)) for x in levels)

    def _fill(
        self, options: dict[str, Any], rng: np.random.Generator, seed: int | None
    ) -> int | None:
        if "traffic_level" not in options:
            options["traffic_level"] = draw_level(rng, self.levels)
        return seed


class SeedPool(_EpisodeOptions):
    """The simulation seed of each episode from ``size`` seeds (:data:`SEED_POOL_BASE` on),
    whose warm-up states are cached after their first use; a seed given to ``reset`` seeds
    the draws and the first episode draws too.

    It passes a seed to ``reset`` of the env it wraps every episode, which would reseed the
    other curriculum wrappers each time: it goes inside them, directly around the env.

    Args:
        env: the environment to wrap.
        size: how many seeds the pool holds.

    Raises:
        ValueError: if ``size`` < 1 or ``env`` holds another curriculum wrapper.
    """

    def __init__(self, env: gym.Env[Obs, Act], size: int) -> None:
        inner: gym.Env[Any, Any] = env
        while isinstance(inner, gym.Wrapper):
            if isinstance(inner, _EpisodeOptions):
                raise ValueError(
                    f"SeedPool goes inside the other curriculum wrappers, not around "
                    f"{type(inner).__name__}"
                )
            inner = inner.env
        super().__init__(env, salt=104)
        if size < 1:
            raise ValueError(f"SeedPool size must be >= 1, got {size}")
        self.size = size

    def _fill(
        self, options: dict[str, Any], rng: np.random.Generator, seed: int | None
    ) -> int | None:
        return draw_seed(rng, self.size)


__all__ = [
    "SEED_POOL_BASE",
    "CommandSchedule",
    "RandomTraffic",
    "SeedPool",
    "StopInjection",
]
