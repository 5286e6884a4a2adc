"""Which trained networks to ship: the project's rule, applied to validation figures.

Each candidate is a trained network (bare, ``--no-shield``) with its figures on the four
validation grids (:data:`GRIDS`): seeds 1000-1009 x the five traffic levels with the stops
at 60-75 and 150-165 s, the same without stops, and the same with observation noise of
2 m / 0.6 m/s and of 3 m / 0.9 m/s. The validation seeds are disjoint from the evaluation
seeds the README reports and from the training pool. A candidate comes before another by,
in turn:

1. **violations**: fewer collisions, red-light runs, pedestrian-yield violations, speeding
   steps and stops over their bound, summed over the grids; under the heavier noise
   speeding steps are not counted (a driver is asked not to speed up to 2 m / 0.6 m/s of
   noise, and to stay clear of other road users and red lights under any noise);
2. **shortfall**: a smaller sum of the relative shortfalls of the ride targets
   (:func:`targets`) on the noise-free grid, against SUMO's Krauss (fast) and IDM (comfort)
   on the same episodes; a met target counts 0, so a candidate is not paid for beating a
   target, and one missed by much counts more than one missed by a hair;
3. **objective**: the policy's own aim, the higher mean speed for fast and the lower mean
   jerk for comfort.

A ride switches between the fast and the comfort network within one episode, so the two
shipped networks must decide a yellow light by the same rule (``yellow_leader``):
:func:`choose_pair` takes the pair sharing a rule with the fewest violations, then the
smallest shortfall, then the better fast and the better comfort network. The networks
shipped today are candidates like any other, so a new one replaces them only if it comes
first.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from explaindrive.env.reward import STOP_WINDOW_M
from explaindrive.evaluation.aggregate import Aggregate
from explaindrive.evaluation.spec import AGENTS

GRIDS: tuple[str, ...] = ("stops", "noise_free", "noise", "heavy_noise")
"""The validation grids a candidate is judged on; the ride targets use ``noise_free``."""
SPEEDING_FREE_GRIDS: tuple[str, ...] = ("heavy_noise",)
"""Grids whose speeding steps are not violations."""
MODES: tuple[str, ...] = AGENTS
COMFORT_SPEED_SHARE = 0.95  # of IDM's mean speed
SLOW_SHARE_MAX = 0.10  # of the free-road time below 60 % of the limit
HARD_BRAKES_MAX = 0.5  # per episode, outside STOP
JERK_SHARE_MAX = 0.5  # of IDM's mean jerk
TOLERANCE = 1e-9  # a shortfall below this is rounding, not a miss


def _miss(*shortfalls: float) -> float:
    """The largest shortfall, 0 below :data:`TOLERANCE`."""
    worst = max(0.0, *shortfalls)
    return worst if worst > TOLERANCE else 0.0


@dataclass(frozen=True, slots=True)
class Target:
    """One ride target on one candidate: its figure, the bound and how far it is missed."""

    name: str
    value: float | None
    bound: str
    shortfall: float


def at_least(name: str, value: float, bound: float) -> Target:
    """``value >= bound``; shortfall (bound - value) / bound."""
    miss = _miss((bound - value) / bound) if bound > 0 else 0.0
    return Target(name, value, f">= {bound:.3f}", miss)


def at_most(name: str, value: float, bound: float) -> Target:
    """``value <= bound``; shortfall (value - bound) / bound (the value itself if bound is 0)."""
    miss = _miss((value - bound) / bound if bound > 0 else value)
    return Target(name, value, f"<= {bound:.3f}", miss)


def within(name: str, value: float | None, lo: float, hi: float) -> Target:
    """``lo <= value <= hi``; shortfall (lo - value) / lo or (value - hi) / hi; a figure
    that does not exist (no stop of that kind) misses nothing."""
    if value is None:
        return Target(name, None, f"{lo:g}-{hi:g}", 0.0)
    return Target(name, value, f"{lo:g}-{hi:g}", _miss((lo - value) / lo, (value - hi) / hi))


def violations(a: Aggregate, speeding: bool = True) -> int:
    """Collisions (episodes), red-light runs, pedestrian-yield violations, yield violations,
    stops over their bound and, unless ``speeding`` is false, speeding steps."""
    return (
        a.collision_episodes + a.red_light_runs + a.ped_violations + a.yield_violations
        + a.stop_bound_misses
        + (a.speeding_steps if speeding else 0)
    )  # fmt: skip


def targets(mode: str, a: Aggregate, krauss: Aggregate, idm: Aggregate) -> list[Target]:
    """The ride targets of ``mode`` for figures ``a``, against Krauss's and IDM's figures on
    the same episodes: for fast, mean speed at least Krauss's, hard brakes and acceleration
    reversals at most Krauss's; for comfort, mean speed at least 95 % of IDM's, at most 10 %
    of the free-road time below 60 % of the limit, at most 0.5 hard brakes an episode, at
    most half IDM's mean jerk, and standing 1-5 m before the line at lights and crossings.

    Raises:
        ValueError: for another mode.
    """
    if mode == "fast":
        return [
            at_least("mean speed", a.mean_speed_mps, krauss.mean_speed_mps),
            at_most("hard brakes", a.hard_brakes_per_episode, krauss.hard_brakes_per_episode),
            at_most("reversals", a.reversals_per_min or 0.0, krauss.reversals_per_min or 0.0),
        ]
    if mode == "comfort":
        lo, hi = STOP_WINDOW_M
        return [
            at_least("mean speed", a.mean_speed_mps, COMFORT_SPEED_SHARE * idm.mean_speed_mps),
            at_most("slow free road", a.slow_free_road_share or 0.0, SLOW_SHARE_MAX),
            at_most("hard brakes", a.hard_brakes_per_episode, HARD_BRAKES_MAX),
            at_most("avg jerk", a.avg_jerk_mps3, JERK_SHARE_MAX * idm.avg_jerk_mps3),
            within("standstill at lights", a.light_stop_gap_mean_m, lo, hi),
            within("standstill at crossings", a.crossing_stop_gap_mean_m, lo, hi),
        ]
    raise ValueError(f"unknown mode {mode!r}; expected one of {MODES}")


@dataclass(frozen=True, slots=True)
class Candidate:
    """A trained network and its figures on the validation grids (:data:`GRIDS`)."""

    name: str
    mode: str
    yellow_leader: str
    grids: Mapping[str, Aggregate]

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"{self.name}: unknown mode {self.mode!r}; expected {MODES}")
        missing = [g for g in GRIDS if g not in self.grids]
        if missing:
            raise ValueError(f"{self.name}: no figures for the grid(s) {', '.join(missing)}")


@dataclass(frozen=True, slots=True)
class Judgement:
    """A candidate judged by the rule: the figures its rank is decided by."""

    candidate: Candidate
    violations: int
    targets: tuple[Target, ...]

    @property
    def shortfall(self) -> float:
        """Sum of the targets' relative shortfalls."""
        return sum(t.shortfall for t in self.targets)

    @property
    def met(self) -> int:
        """Targets met."""
        return sum(t.shortfall == 0.0 for t in self.targets)

    @property
    def objective(self) -> float:
        """The policy's own aim, larger is better: mean speed (fast), minus mean jerk
        (comfort), on the noise-free grid."""
        a = self.candidate.grids["noise_free"]
        return a.mean_speed_mps if self.candidate.mode == "fast" else -a.avg_jerk_mps3

    def key(self) -> tuple[int, float, float]:
        """Sort key: smaller comes first."""
        return (self.violations, self.shortfall, -self.objective)


def judge(candidate: Candidate, krauss: Aggregate, idm: Aggregate) -> Judgement:
    """Judge one candidate against the baselines' noise-free figures."""
    total = sum(
        violations(candidate.grids[g], speeding=g not in SPEEDING_FREE_GRIDS) for g in GRIDS
    )
    found = targets(candidate.mode, candidate.grids["noise_free"], krauss, idm)
    return Judgement(candidate, total, tuple(found))


def rank(candidates: Sequence[Candidate], krauss: Aggregate, idm: Aggregate) -> list[Judgement]:
    """The candidates judged and sorted by the rule, best first (ties keep their order)."""
    return sorted((judge(c, krauss, idm) for c in candidates), key=Judgement.key)


@dataclass(frozen=True, slots=True)
class Pair:
    """The fast and the comfort network to ship together."""

    fast: Judgement
    comfort: Judgement

    def key(self) -> tuple[int, float, tuple[int, float, float], tuple[int, float, float]]:
        """Sort key: fewest violations, smallest shortfall, then each network's own key."""
        return (
            self.fast.violations + self.comfort.violations,
            self.fast.shortfall + self.comfort.shortfall,
            self.fast.key(),
            self.comfort.key(),
        )


def choose_pair(candidates: Sequence[Candidate], krauss: Aggregate, idm: Aggregate) -> Pair:
    """The fast and comfort networks to ship: the best pair that decides a yellow by one rule.

    Raises:
        ValueError: if no fast and comfort candidate share a yellow rule.
    """
    judged = rank(candidates, krauss, idm)
    pairs = [
        Pair(f, c)
        for f in judged
        if f.candidate.mode == "fast"
        for c in judged
        if c.candidate.mode == "comfort" and c.candidate.yellow_leader == f.candidate.yellow_leader
    ]
    if not pairs:
        raise ValueError("no fast and comfort candidates decide a yellow by the same rule")
    return min(pairs, key=Pair.key)
