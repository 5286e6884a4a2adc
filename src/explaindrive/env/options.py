"""Per-episode options accepted by ``reset(options=...)``."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from explaindrive.commands import Command
from explaindrive.env.noise import ObservationNoise
from explaindrive.sim.scenario.layout import validate_traffic_level

_KEYS = ("command", "traffic_level", "command_schedule", "obs_noise")


@dataclass(frozen=True, slots=True)
class ResetOptions:
    """Validated reset options.

    Attributes:
        command: command active from the first step.
        traffic_level: demand scale for this episode (``None``: the config's).
        command_schedule: ``(time_s, command)`` switches, time from the episode start.
        noise: the observation noise of this episode (``None``: the config's).
    """

    command: Command = Command.FAST
    traffic_level: float | None = None
    command_schedule: tuple[tuple[float, Command], ...] = ()
    noise: ObservationNoise | None = None

    @classmethod
    def parse(cls, options: Mapping[str, Any] | None) -> ResetOptions:
        """Validate a reset-options mapping.

        Raises:
            ValueError: on unknown keys, unknown commands, bad levels or schedules.
        """
        if not options:
            return cls()
        unknown = sorted(set(options) - set(_KEYS))
        if unknown:
            raise ValueError(f"unknown reset option(s): {', '.join(unknown)}; known: {list(_KEYS)}")
        command = Command.parse(options.get("command", Command.FAST))
        level = options.get("traffic_level")
        if level is not None:
            level = validate_traffic_level(level)
        schedule = parse_schedule(options.get("command_schedule") or ())
        noise = options.get("obs_noise")
        if noise is not None:
            if not isinstance(noise, Sequence) or isinstance(noise, str) or len(noise) != 2:
                raise ValueError(f"obs_noise must be (sd_m, sd_mps), got {noise!r}")
            noise = ObservationNoise(float(noise[0]), float(noise[1]))
        return cls(command=command, traffic_level=level, command_schedule=schedule, noise=noise)


def parse_schedule(items: Sequence[Any]) -> tuple[tuple[float, Command], ...]:
    """Validate ``[(time_s, command), ...]`` and sort it by time.

    Raises:
        ValueError: on a malformed entry, a negative or non-finite time, or an unknown command.
    """
    out: list[tuple[float, Command]] = []
    for item in items:
        if not isinstance(item, Sequence) or isinstance(item, str) or len(item) != 2:
            raise ValueError(f"command schedule entries are (time_s, command) pairs, got {item!r}")
        t, cmd = item
        if isinstance(t, bool) or not isinstance(t, int | float) or not math.isfinite(t) or t < 0:
            raise ValueError(f"command schedule time must be a finite number >= 0, got {t!r}")
        out.append((float(t), Command.parse(cmd)))
    out.sort(key=lambda e: e[0])
    return tuple(out)
