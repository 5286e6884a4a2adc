"""Per-episode evaluation metrics: the one place that defines them.

The paper reports, per episode: SUMO steps, mean speed, average time headway
(TH), average time to collision (TTC), average jerk and AV collisions. We add
red-light runs, pedestrian-yield violations, right-of-way (yield) violations,
speed-limit violations, stop latency and travel time. Feed every ``info`` from ``env.step`` to
:meth:`EpisodeMetrics.update`, then read :meth:`EpisodeMetrics.result`.

Definitions:
    mean speed   mean of the ego speed over all steps [m/s]
    avg TH       mean time headway to the real leader, over steps with a real
                 leader in range and the ego moving at >= 1 m/s (a creeping car
                 has an unbounded headway that says nothing) [s]
    avg TTC      mean TTC to the real leader over the interaction steps: the ego
                 closes in on it and TTC < TTC_INTERACTION_S (10 s); larger
                 TTCs mean no conflict and would swamp the mean [s]
    avg jerk     mean of |jerk| over all steps [m/s^3]
    stop latency for each switch to STOP: steps until the speed reaches 0; a stop
                 misses its bound when it takes more than ceil(v/3) + 2 steps, v
                 being the speed when the command came
    travel time  seconds until the ego left the route (None if it did not)
    ride         the ride-quality figures (free-road speed, hard brakes, reversals, jerk
                 percentiles, standstill gaps): :mod:`explaindrive.env.ride_quality`
    yield viol.  conflict areas entered in front of a foe with priority, within the gap
                 (:mod:`explaindrive.env.violations`)
    violations   collisions + red-light runs + pedestrian-yield violations + yield
                 violations + speeding steps (:attr:`EpisodeResult.violations`)
    by site      the collisions, red-light runs, pedestrian-yield violations, yield
                 violations and speeding steps again (:data:`VIOLATION_KINDS`), split by
                 where they happened: at a signal, a junction without one, a pedestrian
                 crossing without one, or on the free road (:data:`SITES`, judged by
                 :mod:`explaindrive.env.violations`)
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from explaindrive.env.ride_quality import RideQuality, RideQualityResult

TTC_INTERACTION_S = 10.0  # [s] TTCs at or above this are not counted as interactions
MOVING_SPEED_MPS = 1.0  # [m/s] headways are averaged over steps at or above this speed
SITES: tuple[str, ...] = ("signal", "yield_junction", "crossing", "free_road")
"""Where a step's violations happened (:mod:`explaindrive.env.violations` judges it)."""
VIOLATION_KINDS: tuple[str, ...] = (
    "collisions", "red_light_runs", "ped_violations", "yield_violations", "speeding_steps",
)  # fmt: skip
"""The violation counts of :class:`EpisodeResult`, as split by site (in this order)."""
_INFO_FLAGS = (  # the step's ``info`` flag of each kind, in that order
    "collision", "red_light_run", "ped_violation", "yield_violation", "speeding",
)  # fmt: skip


def no_violations_by_site() -> dict[str, dict[str, int]]:
    """Site -> violation kind -> 0, for every site and kind."""
    return {site: dict.fromkeys(VIOLATION_KINDS, 0) for site in SITES}


def full_split(by_site: dict[str, dict[str, int]]) -> dict[str, dict[str, int]]:
    """A stored split by site with every kind of :data:`VIOLATION_KINDS`, in their order: a
    kind it lacks (a file written before the kind was counted) is 0. An empty split (written
    before sites were recorded) stays empty.

    Raises:
        KeyError: for a site not in :data:`SITES` or a kind not in :data:`VIOLATION_KINDS`.
    """
    if not by_site:
        return {}
    split = no_violations_by_site()
    for site, counts in by_site.items():
        for kind, n in counts.items():
            if kind not in split[site]:
                raise KeyError(f"unknown violation kind {kind!r}")
            split[site][kind] = int(n)
    return split


@dataclass(frozen=True, slots=True)
class EpisodeResult:
    """Figures of one episode."""

    steps: int
    mean_speed_mps: float
    avg_headway_s: float | None
    avg_ttc_s: float | None
    avg_jerk_mps3: float
    collisions: int
    red_light_runs: int
    ped_violations: int
    speeding_steps: int
    stop_latencies: tuple[int, ...]
    unfinished_stops: int
    stop_bound_misses: int
    distance_m: float
    travel_time_s: float | None
    total_reward: float
    ride: RideQualityResult = field(default_factory=lambda: RideQuality().result())
    violations_by_site: dict[str, dict[str, int]] = field(default_factory=dict)
    """Site -> kind -> count (module docstring); empty for an episode stored before sites
    were recorded."""
    yield_violations: int = 0
    """Conflict areas entered in front of a foe with priority, within the gap
    (:mod:`explaindrive.env.violations`); in :attr:`violations` and split by site like the
    other kinds (0 for an episode stored before it was counted)."""

    @property
    def violations(self) -> int:
        """Collisions plus every rule violation (:data:`VIOLATION_KINDS`)."""
        return (
            self.collisions + self.red_light_runs + self.ped_violations + self.yield_violations
            + self.speeding_steps
        )  # fmt: skip

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        d = asdict(self)
        d["stop_latencies"] = list(self.stop_latencies)
        d["ride"] = self.ride.as_dict()
        d["violations_by_site"] = {site: dict(n) for site, n in self.violations_by_site.items()}
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> EpisodeResult:
        """The inverse of :meth:`as_dict` (an evaluation file's episode ``metrics``); a file
        written before yield violations were counted reads as none (:func:`full_split`).

        Raises:
            KeyError, TypeError: for a dict that lacks a field or holds another.
        """
        return cls(
            **{
                **d,
                "stop_latencies": tuple(d["stop_latencies"]),
                "ride": RideQualityResult.from_dict(d["ride"]),
                "violations_by_site": full_split(d.get("violations_by_site", {})),
            }
        )


def _mean(values: list[float]) -> float | None:
    return sum(values) / len(values) if values else None


@dataclass(slots=True)
class EpisodeMetrics:
    """Accumulates step infos into an :class:`EpisodeResult`."""

    speeds: list[float] = field(default_factory=list)
    headways: list[float] = field(default_factory=list)
    ttcs: list[float] = field(default_factory=list)
    jerks: list[float] = field(default_factory=list)
    collisions: int = 0
    red_light_runs: int = 0
    ped_violations: int = 0
    speeding_steps: int = 0
    stop_latencies: list[int] = field(default_factory=list)
    stop_bound_misses: int = 0
    _stop_open: int | None = None
    _stop_bound: int = 0
    distance_m: float = 0.0
    time_s: float = 0.0
    arrived: bool = False
    total_reward: float = 0.0
    _prev_command: str | None = None
    _unfinished: int = 0
    ride: RideQuality = field(default_factory=RideQuality)
    by_site: dict[str, dict[str, int]] = field(default_factory=no_violations_by_site)
    yield_violations: int = 0

    def update(self, info: dict[str, Any], reward: float = 0.0) -> None:
        """Add one step's ``info`` (and reward)."""
        speed = float(info["speed_mps"])
        self.speeds.append(speed)
        self.jerks.append(abs(float(info["jerk_mps3"])))
        headway = float(info["real_headway_s"])
        if math.isfinite(headway) and speed >= MOVING_SPEED_MPS:
            self.headways.append(headway)
        ttc = float(info["real_ttc_s"])
        if ttc < TTC_INTERACTION_S:
            self.ttcs.append(ttc)
        self.collisions += int(bool(info["collision"]))
        self.red_light_runs += int(bool(info["red_light_run"]))
        self.ped_violations += int(bool(info["ped_violation"]))
        self.speeding_steps += int(bool(info["speeding"]))
        self.yield_violations += int(bool(info.get("yield_violation", False)))
        at_site = self.by_site[info["site"]]
        for kind, flag in zip(VIOLATION_KINDS, _INFO_FLAGS, strict=True):
            at_site[kind] += int(bool(info.get(flag, False)))
        self.distance_m = float(info["distance_m"])
        self.time_s = float(info["time_s"])
        self.arrived = self.arrived or bool(info.get("arrived", False))
        self.total_reward += float(reward)
        self._track_stop(str(info["command"]), speed)
        self.ride.update(info)

    def _track_stop(self, command: str, speed_mps: float) -> None:
        # ``command`` is the command under which this step's action was taken.
        if command == "stop" and self._prev_command != "stop":
            self._stop_open = 0
            speed_before = self.speeds[-2] if len(self.speeds) >= 2 else 0.0
            self._stop_bound = stop_latency_bound(speed_before)
        if self._stop_open is not None:
            if command != "stop":
                self._stop_open = None  # cancelled before standstill; counted as unfinished
                self._unfinished += 1
            else:
                self._stop_open += 1
                if speed_mps <= 0.0:
                    self.stop_latencies.append(self._stop_open)
                    self.stop_bound_misses += int(self._stop_open > self._stop_bound)
                    self._stop_open = None
        self._prev_command = command

    def result(self) -> EpisodeResult:
        """The episode's figures."""
        steps = len(self.speeds)
        unfinished = self._unfinished + (1 if self._stop_open is not None else 0)
        return EpisodeResult(
            steps=steps,
            mean_speed_mps=sum(self.speeds) / steps if steps else 0.0,
            avg_headway_s=_mean(self.headways),
            avg_ttc_s=_mean(self.ttcs),
            avg_jerk_mps3=sum(self.jerks) / steps if steps else 0.0,
            collisions=self.collisions,
            red_light_runs=self.red_light_runs,
            ped_violations=self.ped_violations,
            speeding_steps=self.speeding_steps,
            stop_latencies=tuple(self.stop_latencies),
            unfinished_stops=unfinished,
            stop_bound_misses=self.stop_bound_misses,
            distance_m=self.distance_m,
            travel_time_s=self.time_s if self.arrived else None,
            total_reward=self.total_reward,
            ride=self.ride.result(),
            violations_by_site={site: dict(n) for site, n in self.by_site.items()},
            yield_violations=self.yield_violations,
        )


def stop_latency_bound(speed_mps: float) -> int:
    """Steps allowed to reach 0 m/s after a stop command at ``speed_mps``: ceil(v/3) + 2."""
    return math.ceil(speed_mps / 3.0) + 2
