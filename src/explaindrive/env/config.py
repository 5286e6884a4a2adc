"""Typed configuration of the driving environment."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from explaindrive.sim.scenario.layout import validate_traffic_level

EGO_MODELS: tuple[str, ...] = ("agent", "krauss", "idm")


@dataclass(frozen=True, slots=True)
class EnvConfig:
    """Settings of :class:`~explaindrive.env.urban_drive.UrbanDriveEnv`.

    Attributes:
        traffic_level: demand scale; 1.0 = 900 veh/h on the ego's main road.
        max_steps: step limit of an episode (truncation) [steps of 1 s].
        warmup_s: simulated time before the ego enters [s]; the state is cached.
        normalize_obs: return observations scaled into [-1, 1] (see ``env.state``).
        net_file: a SUMO network to use instead of the shipped scenario.
        cache_dir: where generated demand files and warm-up states are kept.
        insert_timeout_s: how long the ego may wait for space to enter [s].
        ego_model: ``"agent"`` (the action sets the speed, SUMO's checks off) or a SUMO
            baseline that drives the ego itself with its safety checks on: ``"krauss"``
            or ``"idm"``. Baselines ignore the action; a STOP command makes SUMO brake to
            a standstill (at most 3 m/s^2) and hold it.
    """

    traffic_level: float = 1.0
    max_steps: int = 1000
    warmup_s: int = 180
    normalize_obs: bool = False
    net_file: Path | None = None
    cache_dir: Path | None = None
    insert_timeout_s: int = 60
    ego_model: str = "agent"

    def __post_init__(self) -> None:
        validate_traffic_level(self.traffic_level)
        for name in ("max_steps", "insert_timeout_s"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        if (
            isinstance(self.warmup_s, bool)
            or not isinstance(self.warmup_s, int)
            or self.warmup_s < 0
        ):
            raise ValueError(f"warmup_s must be an integer >= 0, got {self.warmup_s!r}")
        if self.ego_model not in EGO_MODELS:
            raise ValueError(f"ego_model must be one of {EGO_MODELS}, got {self.ego_model!r}")
        for name in ("net_file", "cache_dir"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, Path):
                object.__setattr__(self, name, Path(value))

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> EnvConfig:
        """Build a config from a mapping, rejecting unknown keys.

        Raises:
            ValueError: on unknown keys or invalid values.
        """
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(
                f"unknown env config key(s): {', '.join(unknown)}; known: {sorted(known)}"
            )
        return cls(**dict(data))
