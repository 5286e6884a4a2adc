"""The paper's reward functions: one place for the constants and one small function per term.

``R0`` (fast)    = R_eff_cf + R_traffic + R_speed(3) + R_collision
``R1`` (comfort) = R_comf_cf + R_traffic + R_speed(1.5) + R_collision
``R2`` (stop)    = r_respect if v = 0; -r_critical if a >= 0; 0 otherwise
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from explaindrive.commands import Command

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


def traffic_rules_reward(*, violation: bool, stopped: bool, stop_reason: str | None) -> float:
    """R_traffic: -r_unsafe for a violation or a stop without reason, +r_respect for a stop
    at a red light or for a pedestrian.

    Args:
        violation: a red light was run or a pedestrian crossing was violated in this step.
        stopped: the ego stands still after the step.
        stop_reason: why standing still is justified: ``"signal"`` (red/yellow light or
            pedestrian, i.e. the virtual leader), ``"queue"`` (a real vehicle close
            ahead) or ``None``.
    """
    if violation:
        return -R_UNSAFE
    if stopped:
        if stop_reason == "signal":
            return R_RESPECT
        if stop_reason is None:
            return -R_UNSAFE
    return 0.0


def collision_reward(collided: bool) -> float:
    """-r_critical on a collision."""
    return -R_CRITICAL if collided else 0.0


def stop_reward(speed_mps: float, speed_change_mps: int) -> float:
    """R2: r_respect at standstill, -r_critical when keeping or raising speed, else 0."""
    if speed_mps <= 0.0:
        return R_RESPECT
    if speed_change_mps >= 0:
        return -R_CRITICAL
    return 0.0


@dataclass(frozen=True, slots=True)
class StepFeatures:
    """Everything a reward needs about one step."""

    speed_mps: float  # ego speed after the step
    speed_change_mps: int  # the action's speed change
    limit_mps: float  # posted limit the agent observed
    ttc_s: float  # w.r.t. the effective (real or virtual) leader
    headway_s: float
    jerk_mps3: float
    violation: bool
    stop_reason: str | None
    collided: bool


@dataclass(frozen=True, slots=True)
class RewardTerms:
    """The terms of one step's reward (all zero when not part of the active reward)."""

    ttc: float = 0.0
    headway: float = 0.0
    jerk: float = 0.0
    traffic: float = 0.0
    speed: float = 0.0
    collision: float = 0.0
    stop: float = 0.0

    @property
    def total(self) -> float:
        """Sum of the terms."""
        return (
            self.ttc
            + self.headway
            + self.jerk
            + self.traffic
            + self.speed
            + self.collision
            + self.stop
        )

    def as_dict(self) -> dict[str, float]:
        """Terms plus ``total`` as a plain dict (for ``info``)."""
        return {
            "ttc": self.ttc,
            "headway": self.headway,
            "jerk": self.jerk,
            "traffic": self.traffic,
            "speed": self.speed,
            "collision": self.collision,
            "stop": self.stop,
            "total": self.total,
        }


def reward_terms(command: Command, f: StepFeatures) -> RewardTerms:
    """The reward of the active command split into its terms."""
    if command is Command.STOP:
        return RewardTerms(stop=stop_reward(f.speed_mps, f.speed_change_mps))
    fast = command is Command.FAST
    w_ttc, w_h = FAST_CF_WEIGHTS if fast else COMFORT_CF_WEIGHTS
    return RewardTerms(
        ttc=w_ttc * f_ttc(f.ttc_s),
        headway=w_h * f_headway(f.headway_s),
        jerk=0.0 if fast else -(f.jerk_mps3**2),
        traffic=traffic_rules_reward(
            violation=f.violation, stopped=f.speed_mps <= 0.0, stop_reason=f.stop_reason
        ),
        speed=speed_reward(
            f.speed_mps, f.limit_mps, FAST_SPEED_WEIGHT if fast else COMFORT_SPEED_WEIGHT
        ),
        collision=collision_reward(f.collided),
    )
