"""Aggregation maths: pure functions over per-episode results.

Conventions (as in the paper's table, which averages over its 25 episodes):
    steps, mean speed, avg jerk   mean over the episodes (``*_std``: population std)
    avg TH, avg TTC               mean of the per-episode averages, over the episodes that
                                  have one (an episode without a leader has no TH)
    collisions                    episodes with an AV collision ("0/25")
    red-light / ped / yield /     totals over the episodes (yield: right-of-way violations;
    speeding                      0 for an episode stored before they were counted)
    violations by site            totals over the episodes, per site and kind (empty when
                                  an episode of the group has no split, e.g. one read from
                                  a file written before sites were recorded)
    stop latency                  over every finished stop of every episode [steps]
    travel time                   mean over the episodes in which the ego reached the end [s]
    ride quality                  pooled over the episodes' steps outside STOP: free-road
                                  speed share and slow share over all free-road steps, hard
                                  brakes per episode and per km, reversals per minute of
                                  following, jerky-step share; p95 jerk is the mean of the
                                  episodes' p95; standstill gaps over every stop of every
                                  episode (definitions: :mod:`explaindrive.env.ride_quality`)
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from explaindrive.env.metrics import EpisodeResult, no_violations_by_site
from explaindrive.env.reward import STOP_WINDOW_M
from explaindrive.env.ride_quality import RideQualityResult


@dataclass(frozen=True, slots=True)
class Aggregate:
    """Figures of a group of episodes (see the module docstring for the conventions)."""

    episodes: int
    steps_mean: float
    steps_std: float
    mean_speed_mps: float
    mean_speed_std: float
    avg_headway_s: float | None
    headway_episodes: int
    avg_ttc_s: float | None
    ttc_episodes: int
    avg_jerk_mps3: float
    collision_episodes: int
    red_light_runs: int
    ped_violations: int
    speeding_steps: int
    speeding_share: float
    stops: int
    unfinished_stops: int
    stop_latency_mean_steps: float | None
    stop_latency_max_steps: int | None
    stop_bound_misses: int
    arrived: int
    travel_time_mean_s: float | None
    free_road_speed_share: float | None = None
    slow_free_road_share: float | None = None
    hard_brakes_per_episode: float = 0.0
    hard_brakes_per_km: float = 0.0
    reversals_per_min: float | None = None
    jerk_p95_mps3: float = 0.0
    jerky_share: float = 0.0
    light_stops: int = 0
    light_stop_gap_mean_m: float | None = None
    crossing_stops: int = 0
    crossing_stop_gap_mean_m: float | None = None
    stop_gap_in_window_share: float | None = None
    yield_violations: int = 0
    """Conflict areas entered in front of a foe with priority, within the gap, in total."""
    violations_by_site: dict[str, dict[str, int]] = field(default_factory=dict)
    """Site -> kind -> total (:data:`~explaindrive.env.metrics.VIOLATION_KINDS`)."""

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return asdict(self)


def mean(values: Iterable[float]) -> float | None:
    """Arithmetic mean, ``None`` for no values."""
    vals = list(values)
    return math.fsum(vals) / len(vals) if vals else None


def pstd(values: Iterable[float]) -> float:
    """Population standard deviation (0 for fewer than two values)."""
    vals = list(values)
    if len(vals) < 2:
        return 0.0
    m = math.fsum(vals) / len(vals)
    return math.sqrt(math.fsum((v - m) ** 2 for v in vals) / len(vals))


def aggregate(results: Sequence[EpisodeResult]) -> Aggregate:
    """Aggregate a group of episodes.

    Raises:
        ValueError: for an empty group.
    """
    if not results:
        raise ValueError("cannot aggregate an empty group of episodes")
    steps = [float(r.steps) for r in results]
    speeds = [r.mean_speed_mps for r in results]
    headways = [r.avg_headway_s for r in results if r.avg_headway_s is not None]
    ttcs = [r.avg_ttc_s for r in results if r.avg_ttc_s is not None]
    latencies = [lat for r in results for lat in r.stop_latencies]
    travel = [r.travel_time_s for r in results if r.travel_time_s is not None]
    total_steps = sum(r.steps for r in results)
    speeding = sum(r.speeding_steps for r in results)
    return Aggregate(
        episodes=len(results),
        steps_mean=math.fsum(steps) / len(steps),
        steps_std=pstd(steps),
        mean_speed_mps=math.fsum(speeds) / len(speeds),
        mean_speed_std=pstd(speeds),
        avg_headway_s=mean(headways),
        headway_episodes=len(headways),
        avg_ttc_s=mean(ttcs),
        ttc_episodes=len(ttcs),
        avg_jerk_mps3=math.fsum(r.avg_jerk_mps3 for r in results) / len(results),
        collision_episodes=sum(1 for r in results if r.collisions > 0),
        red_light_runs=sum(r.red_light_runs for r in results),
        ped_violations=sum(r.ped_violations for r in results),
        speeding_steps=speeding,
        speeding_share=speeding / total_steps if total_steps else 0.0,
        stops=len(latencies),
        unfinished_stops=sum(r.unfinished_stops for r in results),
        stop_latency_mean_steps=mean(float(x) for x in latencies),
        stop_latency_max_steps=max(latencies) if latencies else None,
        stop_bound_misses=sum(r.stop_bound_misses for r in results),
        arrived=len(travel),
        travel_time_mean_s=mean(travel),
        **ride_quality([r.ride for r in results], math.fsum(r.distance_m for r in results)),
        yield_violations=sum(r.yield_violations for r in results),
        violations_by_site=violations_by_site(results),
    )


def violations_by_site(results: Sequence[EpisodeResult]) -> dict[str, dict[str, int]]:
    """The episodes' violations per site and kind, summed; empty if one has no split."""
    if not results or any(not r.violations_by_site for r in results):
        return {}
    total = no_violations_by_site()
    for r in results:
        for site, counts in r.violations_by_site.items():
            for kind, n in counts.items():
                total[site][kind] += n
    return total


def ride_quality(rides: Sequence[RideQualityResult], distance_m: float) -> dict[str, Any]:
    """The ride-quality fields of :class:`Aggregate` (see the module docstring)."""
    free = sum(r.free_road_steps for r in rides)
    following = sum(r.following_steps for r in rides)
    steps = sum(r.steps for r in rides)
    brakes = sum(r.hard_brakes for r in rides)
    lights = [g for r in rides for g in r.light_stop_gaps_m]
    crossings = [g for r in rides for g in r.crossing_stop_gaps_m]
    lo, hi = STOP_WINDOW_M
    in_window = [lo <= g <= hi for g in lights + crossings]
    return {
        "free_road_speed_share": math.fsum(r.free_road_speed_sum for r in rides) / free
        if free
        else None,
        "slow_free_road_share": sum(r.slow_free_road_steps for r in rides) / free if free else None,
        "hard_brakes_per_episode": brakes / len(rides) if rides else 0.0,
        "hard_brakes_per_km": brakes / (distance_m / 1000.0) if distance_m > 0 else 0.0,
        "reversals_per_min": sum(r.reversals for r in rides) / (following / 60.0)
        if following
        else None,
        "jerk_p95_mps3": math.fsum(r.jerk_p95_mps3 for r in rides) / len(rides) if rides else 0.0,
        "jerky_share": sum(r.jerky_steps for r in rides) / steps if steps else 0.0,
        "light_stops": len(lights),
        "light_stop_gap_mean_m": mean(lights),
        "crossing_stops": len(crossings),
        "crossing_stop_gap_mean_m": mean(crossings),
        "stop_gap_in_window_share": sum(in_window) / len(in_window) if in_window else None,
    }


def aggregate_by_level(
    items: Sequence[tuple[float, EpisodeResult]],
) -> dict[float, Aggregate]:
    """Aggregate ``(traffic level, result)`` pairs per level, levels in ascending order."""
    groups: dict[float, list[EpisodeResult]] = {}
    for level, result in items:
        groups.setdefault(float(level), []).append(result)
    return {level: aggregate(groups[level]) for level in sorted(groups)}


@dataclass(frozen=True, slots=True)
class SpeedBand:
    """Mean ego speed over time with its spread across episodes.

    At step ``t`` only the episodes still running are counted (``count[t]``).
    """

    time_s: NDArray[np.float64]
    mean_mps: NDArray[np.float64]
    std_mps: NDArray[np.float64]
    count: NDArray[np.int64]


def speed_band(traces: Sequence[Sequence[float]], step_s: float = 1.0) -> SpeedBand:
    """Per-step mean and population std of speed traces of different lengths.

    Step ``i`` of a trace is the speed after ``i + 1`` steps, at ``(i + 1) * step_s``.

    Raises:
        ValueError: if there are no traces or all are empty.
    """
    length = max((len(t) for t in traces), default=0)
    if length == 0:
        raise ValueError("speed_band needs at least one non-empty trace")
    grid = np.full((len(traces), length), np.nan)
    for i, trace in enumerate(traces):
        grid[i, : len(trace)] = np.asarray(trace, dtype=np.float64)
    count = np.sum(~np.isnan(grid), axis=0).astype(np.int64)
    mean_ = np.nanmean(grid, axis=0)
    std = np.sqrt(np.nanmean((grid - mean_) ** 2, axis=0))
    time_s = (np.arange(length, dtype=np.float64) + 1.0) * step_s
    return SpeedBand(time_s, mean_, std, count)


def command_spans(commands: Sequence[str], step_s: float = 1.0) -> list[tuple[str, float, float]]:
    """Contiguous ``(command, start_s, end_s)`` runs of a per-step command trace."""
    spans: list[tuple[str, float, float]] = []
    for i, cmd in enumerate(commands):
        if spans and spans[-1][0] == cmd:
            spans[-1] = (cmd, spans[-1][1], (i + 1) * step_s)
        else:
            spans.append((cmd, i * step_s, (i + 1) * step_s))
    return spans


def relative_difference(ours: float | None, reference: float | None) -> float | None:
    """``(ours - reference) / reference``; ``None`` if either is missing or reference is 0."""
    if ours is None or reference is None or reference == 0:
        return None
    return (ours - reference) / reference


def levels_of(aggregates: Mapping[float, Aggregate]) -> tuple[float, ...]:
    """The traffic levels of a per-level mapping, ascending."""
    return tuple(sorted(aggregates))


@dataclass(frozen=True, slots=True)
class RunSummary:
    """A named run's aggregates: overall and per traffic level."""

    name: str
    overall: Aggregate
    by_level: dict[float, Aggregate]


def summarize(name: str, items: Sequence[tuple[float, EpisodeResult]]) -> RunSummary:
    """:class:`RunSummary` of ``(traffic level, result)`` pairs.

    Raises:
        ValueError: for no episodes.
    """
    return RunSummary(name, aggregate([r for _l, r in items]), aggregate_by_level(items))
