"""Ride-quality figures: how a drive feels to a passenger, the same for every driver.

Feed every step's ``info`` to :meth:`RideQuality.update` (``EpisodeMetrics`` does) and read
:meth:`RideQuality.result`. Steps driven under a STOP command are left out of every figure
here: braking hard for the passenger's stop is what they asked for.

Definitions (one place; the README, docs/evaluation.md and the tables refer to them):
    free road        a step with no vehicle ahead within :data:`FREE_ROAD_VEHICLE_M` (50 m)
                     and no red or yellow light and no pedestrian on or entering a crossing
                     within :data:`FREE_ROAD_SIGNAL_M` (60 m)
    free-road speed  mean of v / posted limit over free-road steps (a share of the limit)
    slow free road   share of free-road steps below :data:`SLOW_SHARE` (60 %) of the limit
    hard brake       a step braking at :data:`HARD_BRAKE_MPS2` (3 m/s^2) or more; counted
                     per episode and per km driven
    following        a step with a vehicle ahead within :data:`FOLLOWING_M` (50 m)
    reversal         while following, an acceleration of magnitude >= :data:`REVERSAL_MPS2`
                     (2 m/s^2) whose sign is opposite to the previous such acceleration in
                     the same stretch of following; counted per minute of following
    p95 jerk         95th percentile of |jerk| over the episode's steps [m/s^3]
    jerky steps      share of steps with |jerk| >= :data:`JERKY_MPS3` (3 m/s^3)
    standstill gap   each time the car comes to a standstill with a red or yellow light's
                     stop line (or a crossing's, for a pedestrian) as its nearest obstacle,
                     the distance left to that line [m]; kept apart for lights and crossings
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

FREE_ROAD_VEHICLE_M = 50.0  # [m]
FREE_ROAD_SIGNAL_M = 60.0  # [m]
SLOW_SHARE = 0.6  # of the posted limit
HARD_BRAKE_MPS2 = 3.0  # [m/s^2]
FOLLOWING_M = 50.0  # [m]
REVERSAL_MPS2 = 2.0  # [m/s^2]
JERKY_MPS3 = 3.0  # [m/s^3]
RIDE_STANDSTILL_MPS = 0.1  # [m/s] at or below this SUMO's true speed stands (standstill gaps)
_EPS = 1e-6


@dataclass(frozen=True, slots=True)
class RideQualityResult:
    """Ride-quality figures of one episode (steps under STOP left out)."""

    steps: int  # steps outside STOP
    free_road_steps: int
    free_road_speed_sum: float  # sum of v / limit over free-road steps
    slow_free_road_steps: int
    hard_brakes: int
    following_steps: int
    reversals: int
    jerk_p95_mps3: float
    jerky_steps: int
    light_stop_gaps_m: tuple[float, ...]
    crossing_stop_gaps_m: tuple[float, ...]

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict (the stop gaps as lists)."""
        d = asdict(self)
        d["light_stop_gaps_m"] = list(self.light_stop_gaps_m)
        d["crossing_stop_gaps_m"] = list(self.crossing_stop_gaps_m)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> RideQualityResult:
        """The inverse of :meth:`as_dict`.

        Raises:
            KeyError, TypeError: for a dict that lacks a field or holds another.
        """
        gaps = {k: tuple(d[k]) for k in ("light_stop_gaps_m", "crossing_stop_gaps_m")}
        return cls(**{**d, **gaps})


def free_road(real_gap_m: float, light_red_or_yellow: bool, light_gap_m: float,
              crossing_gap_m: float) -> bool:  # fmt: skip
    """No vehicle within 50 m, no red/yellow light or busy crossing within 60 m."""
    if real_gap_m < FREE_ROAD_VEHICLE_M:
        return False
    if light_red_or_yellow and light_gap_m < FREE_ROAD_SIGNAL_M:
        return False
    return crossing_gap_m >= FREE_ROAD_SIGNAL_M


def is_free_road(info: dict[str, Any]) -> bool:
    """:func:`free_road` of a step's ``info``."""
    return free_road(
        float(info["real_gap_m"]),
        info["light_state"] != "green",
        float(info["light_gap_m"]),
        float(info["crossing_gap_m"]),
    )


def signal_stop_kind(info: dict[str, Any]) -> str | None:
    """``"light"`` or ``"crossing"`` when the car's nearest obstacle is that stop line, else
    ``None`` (a vehicle ahead, or nothing)."""
    if not info.get("leader_virtual", False):
        return None
    gap = float(info["gap_m"])
    if info["light_state"] != "green" and abs(float(info["light_gap_m"]) - gap) < 0.5:
        return "light"
    if abs(float(info["crossing_gap_m"]) - gap) < 0.5:
        return "crossing"
    return None


@dataclass(slots=True)
class RideQuality:
    """Accumulates step infos into a :class:`RideQualityResult`."""

    steps: int = 0
    free_road_steps: int = 0
    free_road_speed_sum: float = 0.0
    slow_free_road_steps: int = 0
    hard_brakes: int = 0
    following_steps: int = 0
    reversals: int = 0
    jerky_steps: int = 0
    jerks: list[float] = field(default_factory=list)
    light_gaps: list[float] = field(default_factory=list)
    crossing_gaps: list[float] = field(default_factory=list)
    _last_sign: int = 0  # sign of the last strong acceleration while following
    _prev_speed: float = 0.0

    def update(self, info: dict[str, Any]) -> None:
        """Add one step's ``info``."""
        speed = float(info["speed_mps"])
        prev, self._prev_speed = self._prev_speed, speed
        if info["command"] == "stop":
            self._last_sign = 0
            return
        self.steps += 1
        accel, jerk = float(info["accel_mps2"]), abs(float(info["jerk_mps3"]))
        self.jerks.append(jerk)
        self.jerky_steps += int(jerk >= JERKY_MPS3 - _EPS)
        self.hard_brakes += int(accel <= -HARD_BRAKE_MPS2 + _EPS)
        if is_free_road(info):
            share = speed / float(info["posted_limit_mps"])
            self.free_road_steps += 1
            self.free_road_speed_sum += share
            self.slow_free_road_steps += int(share < SLOW_SHARE)
        self._track_following(info, accel)
        if speed <= RIDE_STANDSTILL_MPS < prev:
            kind = signal_stop_kind(info)
            if kind == "light":
                self.light_gaps.append(float(info["gap_m"]))
            elif kind == "crossing":
                self.crossing_gaps.append(float(info["gap_m"]))

    def _track_following(self, info: dict[str, Any], accel: float) -> None:
        if float(info["real_gap_m"]) >= FOLLOWING_M:
            self._last_sign = 0
            return
        self.following_steps += 1
        if abs(accel) >= REVERSAL_MPS2 - _EPS:
            sign = 1 if accel > 0 else -1
            self.reversals += int(self._last_sign == -sign)
            self._last_sign = sign

    def result(self) -> RideQualityResult:
        """The episode's figures."""
        p95 = float(np.percentile(self.jerks, 95)) if self.jerks else 0.0
        return RideQualityResult(
            steps=self.steps,
            free_road_steps=self.free_road_steps,
            free_road_speed_sum=self.free_road_speed_sum,
            slow_free_road_steps=self.slow_free_road_steps,
            hard_brakes=self.hard_brakes,
            following_steps=self.following_steps,
            reversals=self.reversals,
            jerk_p95_mps3=p95 if math.isfinite(p95) else 0.0,
            jerky_steps=self.jerky_steps,
            light_stop_gaps_m=tuple(self.light_gaps),
            crossing_stop_gaps_m=tuple(self.crossing_gaps),
        )
