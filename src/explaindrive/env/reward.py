"""The reward functions: one place for the constants and one small function per term.

The paper's rewards (recipe ``paper``):

``R0`` (fast)    = R_eff_cf + R_traffic + R_speed(3) + R_collision
``R1`` (comfort) = R_comf_cf + R_traffic + R_speed(1.5) + R_collision
``R2`` (stop)    = r_respect if v = 0; -r_critical if a >= 0; 0 otherwise

The ``passenger`` recipe keeps every term and changes weights and where they apply
(:data:`RECIPES`; each change is a row of docs/agent.md's deviations table):

* the headway term pays for following real vehicles only, not for closing in on a stop line;
* a charge per step for time (``time``), so that getting there pays;
* standing for a light or a pedestrian pays only within 1-5 m of the line, and less than
  driving (``signal_stop``, ``stop_window_m``);
* jerk is charged under fast too (lightly), and braking harder than 1 m/s^2 is charged
  (``hard_brake``), more under comfort;
* closing in on a leader, a red light or a pedestrian too fast to stop gently is charged
  (``approach``): the deceleration that would just stop in time, as IDM's braking
  strategy has it, beyond a comfortable 1.5 m/s^2 (1.0 under comfort, charged twice as much
  there), so the car slows down early; behind a
  vehicle the room to stop in keeps a time gap of ``approach_time_gap_s`` at the car's
  speed, as IDM's desired gap does, so that the car eases off before a queue rather than at
  its tail; before a stop line it keeps only the standstill gap, so that a light turning
  yellow ahead calls for the gentlest deceleration that stops at the line, not a harder one;
* driving below 90 % of the limit on a free road is charged (``cruise``): on an open road a
  passenger expects the car to go;
* comfort's progress is worth as much as fast's: the two differ in smoothness.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Annotated

from pydantic import AfterValidator

from explaindrive.commands import Command
from explaindrive.config import FROM_LIST

R_RESPECT = 2.0  # reward for stopping at a red light / for a pedestrian
R_UNSAFE = 10.0  # penalty for violations, speeding and stopping without reason
R_CRITICAL = 50.0  # penalty for collisions (and for not braking under STOP)

TTC_THRESHOLD_S = 2.0  # [s]
TTC_FLOOR_S = 1e-3  # [s] keeps f_TTC finite at a TTC of exactly zero (log(5e-4) = -7.6)
HEADWAY_MU = 0.4226  # lognormal parameters of NGSIM time headways
HEADWAY_SIGMA = 0.4365

FAST_CF_WEIGHTS = (2.0, 3.0)  # (f_TTC, f_headway)
COMFORT_CF_WEIGHTS = (2.0, 1.5)
FAST_SPEED_WEIGHT = 3.0
COMFORT_SPEED_WEIGHT = 1.5
STOP_REASON_GAP_M = 15.0  # [m] a leader this close justifies standing still
GENTLE_BRAKE_MPS2 = 1.0  # [m/s^2] braking up to this is not charged by ``hard_brake``
APPROACH_FREE_DECEL_MPS2 = 1.5  # [m/s^2] ``approach`` charges no stop needing up to this (default)
APPROACH_STANDSTILL_M = 2.0  # [m] the approach aims to stand this far behind the obstacle
MAX_NEEDED_MPS2 = 9.0  # [m/s^2] SUMO's emergency braking: ``approach`` charges no further
CRUISE_SHARE = 0.9  # of the posted limit: ``cruise`` charges free-road driving below it


@dataclass(frozen=True, slots=True)
class RewardWeights:
    """Weights of one driving command's reward (fast or comfort).

    Attributes:
        ttc: weight of f_TTC (w.r.t. the effective leader, stop lines included).
        headway: weight of f_headway.
        headway_on_stop_lines: whether f_headway also pays for a stop line (a virtual
            leader); the paper's reward does.
        speed: weight of v / v_lim.
        time: charge per step [reward/s].
        jerk: weight of -jerk^2.
        hard_brake: weight of -(braking beyond :data:`GENTLE_BRAKE_MPS2`)^2.
        approach: weight of -(needed deceleration beyond ``approach_free_mps2``)^2
            (:func:`approach_penalty`).
        approach_free_mps2: the needed deceleration [m/s^2] ``approach`` does not charge.
        approach_time_gap_s: the time gap [s] at the car's speed that the approach keeps
            clear of a vehicle ahead besides :data:`APPROACH_STANDSTILL_M` (not of a stop
            line).
        cruise: weight of -(:data:`CRUISE_SHARE` - v / v_lim) on a free road below it.
        signal_stop: paid per step standing for a light or a pedestrian.
        stop_window_m: ``(min, max)`` distance to the line within which ``signal_stop`` is
            paid; ``None`` pays it at any distance (the paper).
    """

    ttc: float
    headway: float
    headway_on_stop_lines: bool
    speed: float
    time: float = 0.0
    jerk: float = 0.0
    hard_brake: float = 0.0
    approach: float = 0.0
    approach_free_mps2: float = APPROACH_FREE_DECEL_MPS2
    approach_time_gap_s: float = 0.0
    cruise: float = 0.0
    signal_stop: float = R_RESPECT
    stop_window_m: tuple[float, float] | None = None


@dataclass(frozen=True, slots=True)
class RewardRecipe:
    """The weights of the fast and comfort rewards (stop always uses R2)."""

    name: str
    fast: RewardWeights
    comfort: RewardWeights

    def weights(self, command: Command) -> RewardWeights:
        """The weights of a driving command.

        Raises:
            ValueError: for STOP, whose reward has no weights.
        """
        if command is Command.STOP:
            raise ValueError("the stop reward R2 has no weights")
        return self.fast if command is Command.FAST else self.comfort

    def with_stop_window(self, window_m: tuple[float, float]) -> RewardRecipe:
        """This recipe with standing for a light or a pedestrian paid within ``window_m``
        of the line under both commands (:attr:`RewardWeights.stop_window_m`).

        Raises:
            ValueError: unless ``0 <= min < max``.
        """
        lo, hi = check_stop_window(window_m)
        return replace(
            self,
            fast=replace(self.fast, stop_window_m=(lo, hi)),
            comfort=replace(self.comfort, stop_window_m=(lo, hi)),
        )


def check_stop_window(window_m: tuple[float, float]) -> tuple[float, float]:
    """``window_m`` as floats if ``0 <= min < max`` (metres before the line).

    Raises:
        ValueError: otherwise.
    """
    lo, hi = (float(x) for x in window_m)
    if not (math.isfinite(hi) and 0.0 <= lo < hi):
        raise ValueError(f"a stop window must be [min, max] m with 0 <= min < max, got {[lo, hi]}")
    return lo, hi


PAPER_RECIPE = RewardRecipe(
    "paper",
    fast=RewardWeights(*FAST_CF_WEIGHTS, headway_on_stop_lines=True, speed=FAST_SPEED_WEIGHT),
    comfort=RewardWeights(
        *COMFORT_CF_WEIGHTS, headway_on_stop_lines=True, speed=COMFORT_SPEED_WEIGHT, jerk=1.0
    ),
)
STOP_WINDOW_M = (1.0, 5.0)  # [m] where a car standing for a light or a pedestrian should stand
PASSENGER_RECIPE = RewardRecipe(
    "passenger",
    fast=RewardWeights(
        *FAST_CF_WEIGHTS,
        headway_on_stop_lines=False,
        speed=FAST_SPEED_WEIGHT,
        time=0.75,
        jerk=0.3,
        hard_brake=2.0,
        approach=0.3,
        approach_time_gap_s=1.0,
        cruise=3.0,
        signal_stop=2.0,
        stop_window_m=STOP_WINDOW_M,
    ),
    comfort=RewardWeights(
        *COMFORT_CF_WEIGHTS,
        headway_on_stop_lines=False,
        speed=FAST_SPEED_WEIGHT,
        time=0.5,
        jerk=1.0,
        hard_brake=3.0,
        approach=2.0,
        approach_free_mps2=1.0,
        approach_time_gap_s=1.0,
        cruise=5.0,
        signal_stop=2.0,
        stop_window_m=STOP_WINDOW_M,
    ),
)
StopWindow = Annotated[tuple[float, float], FROM_LIST, AfterValidator(check_stop_window)]
"""A config field holding ``(min_m, max_m)`` before a stop line, ``0 <= min < max``."""
RECIPES: dict[str, RewardRecipe] = {r.name: r for r in (PAPER_RECIPE, PASSENGER_RECIPE)}
REWARD_NAMES: tuple[str, ...] = tuple(RECIPES)


def time_to_collision(gap_m: float, closing_speed_mps: float) -> float:
    """TTC = gap / closing speed [s]; ``inf`` when not closing in (``closing <= 0``)."""
    if closing_speed_mps <= 0.0:
        return math.inf
    return max(gap_m, 0.0) / closing_speed_mps


def time_headway(gap_m: float, leader_length_m: float, speed_mps: float) -> float:
    """H = (gap + leader length) / v_ego [s]; ``inf`` when the ego stands still."""
    if speed_mps <= 0.0:
        return math.inf
    return (gap_m + leader_length_m) / speed_mps


def f_ttc(ttc_s: float) -> float:
    """log(ttc / 2) for 0 <= ttc <= 2 s, else 0 (TTC floored at :data:`TTC_FLOOR_S`)."""
    if 0.0 <= ttc_s <= TTC_THRESHOLD_S:
        return math.log(max(ttc_s, TTC_FLOOR_S) / TTC_THRESHOLD_S)
    return 0.0


def f_headway(headway_s: float) -> float:
    """Lognormal density of the headway (mu 0.4226, sigma 0.4365); 0 for h <= 0 or inf."""
    if not 0.0 < headway_s < math.inf:
        return 0.0
    z = (math.log(headway_s) - HEADWAY_MU) / HEADWAY_SIGMA
    return math.exp(-0.5 * z * z) / (headway_s * HEADWAY_SIGMA * math.sqrt(2.0 * math.pi))


def jerk(accel_mps2: float, prev_accel_mps2: float, dt_s: float = 1.0) -> float:
    """(a_t - a_{t-1}) / dt [m/s^3]."""
    return (accel_mps2 - prev_accel_mps2) / dt_s


def speed_reward(speed_mps: float, limit_mps: float, weight: float) -> float:
    """-r_unsafe above the limit, else weight * v / v_lim."""
    if speed_mps > limit_mps:
        return -R_UNSAFE
    return weight * speed_mps / limit_mps if limit_mps > 0 else 0.0


def traffic_rules_reward(
    *,
    violation: bool,
    stopped: bool,
    stop_reason: str | None,
    signal_stop: float = R_RESPECT,
) -> float:
    """R_traffic: -r_unsafe for a violation or a stop without reason, ``signal_stop``
    (the paper: +r_respect) for a stop at a red light or for a pedestrian.

    Args:
        violation: a red light was run, a pedestrian crossing was violated or a conflict
            area was entered in front of a foe with priority (a yield violation) in this
            step.
        stopped: the ego stands still after the step.
        stop_reason: why standing still is justified: ``"signal"`` (red/yellow light or
            pedestrian, i.e. the virtual leader), ``"queue"`` (a real vehicle close
            ahead) or ``None``.
        signal_stop: what a stop for a signal pays.
    """
    if violation:
        return -R_UNSAFE
    if stopped:
        if stop_reason == "signal":
            return signal_stop
        if stop_reason is None:
            return -R_UNSAFE
    return 0.0


def hard_brake_penalty(accel_mps2: float, weight: float) -> float:
    """-weight * (braking beyond :data:`GENTLE_BRAKE_MPS2`)^2; 0 for gentler braking."""
    excess = max(0.0, -accel_mps2 - GENTLE_BRAKE_MPS2)
    return -weight * excess * excess


def needed_deceleration(gap_m: float, closing_speed_mps: float, keep_m: float = 0.0) -> float:
    """The constant deceleration [m/s^2] that just stops the closing-in before the gap
    shrinks to :data:`APPROACH_STANDSTILL_M` plus ``keep_m``: dv^2 / (2 (gap - s0 - keep))
    (IDM's kinematic deceleration); 0 when not closing in, and the room floored at 0.5 m."""
    if closing_speed_mps <= 0.0 or not math.isfinite(gap_m):
        return 0.0
    room = max(gap_m - APPROACH_STANDSTILL_M - keep_m, 0.5)
    return closing_speed_mps * closing_speed_mps / (2.0 * room)


def approach_penalty(
    gap_m: float,
    closing_speed_mps: float,
    weight: float,
    keep_m: float = 0.0,
    free_mps2: float = APPROACH_FREE_DECEL_MPS2,
) -> float:
    """-weight * (needed deceleration beyond ``free_mps2``)^2, stopping ``keep_m`` short of
    the standstill gap; the need is capped at :data:`MAX_NEEDED_MPS2`."""
    needed = min(needed_deceleration(gap_m, closing_speed_mps, keep_m), MAX_NEEDED_MPS2)
    excess = max(0.0, needed - free_mps2)
    return -weight * excess * excess


def cruise_penalty(speed_mps: float, limit_mps: float, free_road: bool, weight: float) -> float:
    """-weight * (:data:`CRUISE_SHARE` - v / v_lim) on a free road below that share, else 0."""
    if not free_road or limit_mps <= 0.0:
        return 0.0
    return -weight * max(0.0, CRUISE_SHARE - speed_mps / limit_mps)


def collision_reward(collided: bool) -> float:
    """-r_critical on a collision."""
    return -R_CRITICAL if collided else 0.0


def stop_reward(speed_mps: float, speed_change_mps: float) -> float:
    """R2: r_respect at standstill, -r_critical when keeping or raising speed, else 0."""
    if speed_mps <= 0.0:
        return R_RESPECT
    if speed_change_mps >= 0:
        return -R_CRITICAL
    return 0.0


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class StepFeatures:
    """Everything a reward needs about one step."""

    speed_mps: float  # ego speed after the step
    speed_change_mps: float  # the speed change applied (through the speed limiter, if on)
    limit_mps: float  # posted limit the agent observed
    ttc_s: float  # w.r.t. the effective (real or virtual) leader
    headway_s: float  # w.r.t. the effective leader
    jerk_mps3: float
    violation: bool  # a red-light run, pedestrian-yield or yield violation in the step
    stop_reason: str | None
    collided: bool
    real_headway_s: float = math.inf  # w.r.t. the real leader (inf without one)
    accel_mps2: float | None = None  # the step's speed change as driven; None: the action's
    leader_gap_m: float = math.inf  # gap to the effective leader after the step [m]
    leader_virtual: bool = False  # the effective leader is a stop line (light or crossing)
    closing_speed_mps: float = 0.0  # ego speed minus the effective leader's, after the step
    free_road: bool = False  # as the ride-quality figures define it (env/ride_quality.py)


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class RewardTerms:
    """The terms of one step's reward (all zero when not part of the active reward)."""

    ttc: float = 0.0
    headway: float = 0.0
    jerk: float = 0.0
    traffic: float = 0.0
    speed: float = 0.0
    collision: float = 0.0
    stop: float = 0.0
    time: float = 0.0
    brake: float = 0.0
    approach: float = 0.0
    cruise: float = 0.0

    @property
    def total(self) -> float:
        """Sum of the terms."""
        return math.fsum([getattr(self, name) for name in TERM_NAMES])

    def as_dict(self) -> dict[str, float]:
        """Terms plus ``total`` as a plain dict (for ``info``)."""
        terms = {name: getattr(self, name) for name in TERM_NAMES}
        terms["total"] = math.fsum(terms.values())
        return terms


TERM_NAMES: tuple[str, ...] = tuple(f.name for f in fields(RewardTerms))
"""The names of the :class:`RewardTerms`, in their order."""


def _signal_stop(w: RewardWeights, gap_m: float) -> float:
    """What standing for a signal pays at ``gap_m`` before its line."""
    if w.stop_window_m is None:
        return w.signal_stop
    lo, hi = w.stop_window_m
    return w.signal_stop if lo <= gap_m <= hi else 0.0


def reward_terms(
    command: Command, f: StepFeatures, recipe: RewardRecipe = PAPER_RECIPE
) -> RewardTerms:
    """The reward of the active command under ``recipe``, split into its terms."""
    if command is Command.STOP:
        return RewardTerms(stop=stop_reward(f.speed_mps, f.speed_change_mps))
    w = recipe.weights(command)
    headway = f.headway_s if w.headway_on_stop_lines else f.real_headway_s
    accel = float(f.speed_change_mps) if f.accel_mps2 is None else f.accel_mps2
    return RewardTerms(
        ttc=w.ttc * f_ttc(f.ttc_s),
        headway=w.headway * f_headway(headway),
        jerk=-w.jerk * f.jerk_mps3**2,
        traffic=traffic_rules_reward(
            violation=f.violation,
            stopped=f.speed_mps <= 0.0,
            stop_reason=f.stop_reason,
            signal_stop=_signal_stop(w, f.leader_gap_m),
        ),
        speed=speed_reward(f.speed_mps, f.limit_mps, w.speed),
        collision=collision_reward(f.collided),
        time=-w.time,
        brake=hard_brake_penalty(accel, w.hard_brake),
        approach=approach_penalty(
            f.leader_gap_m,
            f.closing_speed_mps,
            w.approach,
            0.0 if f.leader_virtual else w.approach_time_gap_s * f.speed_mps,
            w.approach_free_mps2,
        ),
        cruise=cruise_penalty(f.speed_mps, f.limit_mps, f.free_road, w.cruise),
    )
