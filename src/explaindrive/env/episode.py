"""One episode's bookkeeping and one step's record, from which the reward and the ``info``
are computed."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import STEP_LENGTH_S
from explaindrive.env.lights import AmberDecision
from explaindrive.env.noise import ObservationNoise
from explaindrive.env.perception import Leader, Percept, Perception
from explaindrive.env.reward import (
    STOP_REASON_GAP_M,
    StepFeatures,
    time_headway,
    time_to_collision,
)
from explaindrive.env.sumo_process import Motion
from explaindrive.env.violations import ViolationJudge, Violations, speeding
from explaindrive.sim.pedestrians import KerbYield, PedestrianSource


@dataclass(slots=True)
class Episode:
    """Mutable per-episode bookkeeping.

    Attributes:
        command: the active command.
        schedule: the command switches still to come, ``(time_s, command)`` by time.
        start_pos_m: the ego's route position at entry [m].
        perception: the ego's sensors for this episode.
        judge: the stop-line violation judge for this episode.
        seen: the latest perception (what the ego saw before the next step).
        steps: steps taken.
        speed_mps: the ego's speed after the latest step.
        accel_mps2: its latest acceleration.
        pos_m: its front's route position [m].
        done: the episode has terminated or been truncated.
    """

    command: Command
    schedule: list[tuple[float, Command]]
    start_pos_m: float
    perception: Perception
    judge: ViolationJudge
    seen: Percept | None = None
    steps: int = 0
    speed_mps: float = 0.0
    accel_mps2: float = 0.0
    pos_m: float = 0.0
    done: bool = False
    pedestrians: PedestrianSource | None = None
    kerb: KerbYield = field(default_factory=KerbYield)
    amber: AmberDecision = field(default_factory=AmberDecision)
    noise: ObservationNoise = field(default_factory=ObservationNoise)
    noise_rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))

    @property
    def light_colour(self) -> S.LightState:
        """The true colour of the next light in the latest perception (green before any)."""
        return self.seen.light_colour if self.seen is not None else S.LightState.GREEN

    @property
    def yield_gap_m(self) -> float:
        """[m] to the yield line the latest perception holds the ego at as a virtual leader
        (``YieldReading.leader_gap_m``; the sensor range: none)."""
        return self.seen.yields.leader_gap_m if self.seen is not None else S.SENSOR_RANGE_M

    @property
    def time_s(self) -> float:
        """Seconds since the ego entered."""
        return self.steps * STEP_LENGTH_S

    def apply_schedule(self) -> None:
        """Switch to the scheduled commands that are due."""
        now_s = self.time_s
        while self.schedule and self.schedule[0][0] <= now_s + 1e-9:
            self.command = self.schedule.pop(0)[1]


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class StepRecord:
    """Everything one step produced that the reward and the info are computed from.

    Attributes:
        command: the command the action was taken under.
        change: the speed change applied [m/s]: the action's, or with the speed limiter
            on the one it let through (:func:`~explaindrive.env.actions.limited_change`:
            +1 at 13 m/s under a 13.89 m/s limit applies +0.89); SUMO's own, rounded, for
            the baselines. The reward reads it only under STOP, for its sign, which the
            limiter never changes (a rise it cuts stays >= 0); the ride-quality figures and
            the reward's braking terms read ``accel``, the change as driven.
        accel: the ego's acceleration over the step [m/s^2].
        jerk: its change from the previous step's [m/s^3].
        motion: what the simulation did with the ego.
        leader: the effective leader after the step.
        real: the real leader after the step.
        limit_mps: the posted limit the agent observed before the step.
        violations: the stop-line violations of the step.
        free_road: the road ahead is free after the step
            (:func:`explaindrive.env.ride_quality.free_road`).
    """

    command: Command
    change: float
    accel: float
    jerk: float
    motion: Motion
    leader: Leader | None
    real: Leader | None
    limit_mps: float
    violations: Violations
    free_road: bool = False

    def features(self) -> StepFeatures:
        """What the reward needs, w.r.t. the effective (real or virtual) leader."""
        leader, real, v = self.leader, self.real, self.motion.speed_mps
        stop_reason: str | None = None
        if leader is not None and leader.gap_m <= STOP_REASON_GAP_M:
            stop_reason = "signal" if leader.virtual else "queue"
        return StepFeatures(
            speed_mps=v,
            speed_change_mps=self.change,
            limit_mps=self.limit_mps,
            ttc_s=time_to_collision(leader.gap_m, v - leader.speed_mps) if leader else math.inf,
            headway_s=time_headway(leader.gap_m, leader.length_m, v) if leader else math.inf,
            jerk_mps3=self.jerk,
            violation=self.violations.any,
            stop_reason=stop_reason,
            collided=self.motion.collided,
            real_headway_s=time_headway(real.gap_m, real.length_m, v) if real else math.inf,
            accel_mps2=self.accel,
            leader_gap_m=leader.gap_m if leader else math.inf,
            leader_virtual=leader.virtual if leader else False,
            closing_speed_mps=v - leader.speed_mps if leader else 0.0,
            free_road=self.free_road,
        )

    def info(
        self,
        ep: Episode,
        obs: np.ndarray,
        legal_limit_mps: float,
        features: StepFeatures,
        terms: dict[str, float],
    ) -> dict[str, Any]:
        """The step's ``info``: command, kinematics, leaders, safety events, reward terms.

        Args:
            ep: the episode after the step.
            obs: the raw observation after the step.
            legal_limit_mps: the legal limit at the ego's position after the step.
            features: the step's :meth:`features`.
            terms: the step's reward terms (:meth:`RewardTerms.as_dict`).
        """
        v, real = self.motion.speed_mps, self.real
        return {
            "command": self.command.label,
            "next_command": ep.command.label,
            "time_s": ep.time_s,
            "speed_mps": v,
            "speed_change_mps": self.change,
            "accel_mps2": self.accel,
            "jerk_mps3": self.jerk,
            "limit_mps": legal_limit_mps,
            "posted_limit_mps": self.limit_mps,
            "gap_m": features.leader_gap_m,
            "leader_virtual": features.leader_virtual,
            "ttc_s": features.ttc_s,
            "headway_s": features.headway_s,
            "real_gap_m": real.gap_m if real else math.inf,
            "real_ttc_s": time_to_collision(real.gap_m, v - real.speed_mps) if real else math.inf,
            "real_headway_s": features.real_headway_s,
            "real_leader_speed_mps": real.speed_mps if real else math.inf,
            "light_gap_m": float(obs[S.D_TL]),
            "light_state": ep.light_colour.label,
            "crossing_gap_m": float(obs[S.D_CROSS]),
            "yield_gap_m": ep.yield_gap_m,
            "distance_m": ep.pos_m - ep.start_pos_m,
            "collision": self.motion.collided,
            "red_light_run": self.violations.red_light_run,
            "ped_violation": self.violations.ped_violation,
            "yield_violation": self.violations.yield_violation,
            "speeding": speeding(v, legal_limit_mps),
            "site": self.violations.site,
            "arrived": self.motion.arrived,
            "reward_terms": terms,
        }
