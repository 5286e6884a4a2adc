"""``explaindrive/UrbanDrive-v0``: longitudinal control of the ego car in the urban SUMO scenario.

Each step is 1 s. The action changes the ego speed by -3..+3 m/s; SUMO's own
safety checks for the ego are off (speed mode 0), so collisions, red-light runs,
pedestrian-yield and speed-limit violations can happen and are counted.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
import traci.constants as tc
from numpy.typing import NDArray

from explaindrive.cache import cache_dir as user_cache_dir
from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.actions import (
    N_ACTIONS,
    STEP_LENGTH_S,
    speed_change,
    stopping_need,
)
from explaindrive.env.config import EnvConfig
from explaindrive.env.lights import AmberDecision
from explaindrive.env.noise import ObservationNoise
from explaindrive.env.options import ResetOptions
from explaindrive.env.reward import (
    RECIPES,
    STOP_REASON_GAP_M,
    RewardTerms,
    StepFeatures,
    reward_terms,
    time_headway,
    time_to_collision,
)
from explaindrive.env.warm_start import restore_warm_state, sumo_args
from explaindrive.sim.connection import SumoConnection
from explaindrive.sim.crossing_lanes import CrossingLane, crossing_lanes, pedestrian_in_lane
from explaindrive.sim.pedestrians import KerbYield, PedestrianSource
from explaindrive.sim.route import RouteCrossing, RouteGeometry, RouteLight, load_route_geometry
from explaindrive.sim.scenario.files import (
    BASELINE_EGO_TYPES,
    EGO_ID,
    EGO_ROUTE_ID,
    EGO_TYPE_ID,
    ScenarioFiles,
)
from explaindrive.sim.scenario.limits import SATURATED_LEVEL, SEED_LIMIT, validate_seed
from explaindrive.sim.scenario.source import ScenarioSource

log = logging.getLogger(__name__)

_EGO_VARS = (tc.VAR_SPEED, tc.VAR_DISTANCE, tc.VAR_LEADER)
_EGO_LANE_VARS = (*_EGO_VARS, tc.VAR_LANE_ID)  # where SUMO changes the ego's lanes
_SIM_VARS = (tc.VAR_ARRIVED_VEHICLES_IDS, tc.VAR_COLLIDING_VEHICLES_IDS)
EGO_LENGTH_M = 5.0  # [m] as in the ego vType
ENTRY_CLEAR_AFTER_S = 10  # [s] the entry stretch is cleared after every such wait for a gap
ENTRY_CLEAR_M = 30.0  # [m] length of that stretch
BACKLOG_DROP_AFTER_S = 30  # [s] after this wait the vehicles queued to enter there go too
JUDGE_CROSSING_M = S.MAX_SPEED_MPS + 5.0  # [m] a crossing this close may be entered next step
STRATEGIC_LANE_CHANGES = 0b011000000001  # SUMO lane-change mode: strategic changes only
_LOW: tuple[float, ...] = tuple(float(x) for x in S.STATE_LOW)
_HIGH: tuple[float, ...] = tuple(float(x) for x in S.STATE_HIGH)


@dataclass(slots=True)
class _Leader:
    gap_m: float
    speed_mps: float
    length_m: float
    virtual: bool


@dataclass(frozen=True, slots=True)
class _Motion:
    """Outcome of one simulated step for the ego."""

    speed_mps: float
    collided: bool
    arrived: bool
    ego: Any  # the ego's subscription results; None once it has left the simulation


@dataclass(frozen=True, slots=True)
class _Step:
    """Everything one step produced that the reward and the info are computed from."""

    command: Command
    change: int
    accel: float
    jerk: float
    motion: _Motion
    leader: _Leader | None
    real: _Leader | None
    limit_mps: float  # the posted limit the agent observed before the step
    red_run: bool
    ped_violation: bool

    @property
    def ttc_s(self) -> float:
        """TTC w.r.t. the effective leader (inf without one)."""
        if self.leader is None:
            return math.inf
        return time_to_collision(self.leader.gap_m, self.motion.speed_mps - self.leader.speed_mps)


@dataclass(slots=True)
class _Episode:
    """Mutable per-episode bookkeeping."""

    command: Command
    schedule: list[tuple[float, Command]]
    start_pos_m: float
    steps: int = 0
    speed_mps: float = 0.0
    accel_mps2: float = 0.0
    pos_m: float = 0.0
    light_state: dict[str, S.LightState] = field(default_factory=dict)
    occupied: dict[str, bool] = field(default_factory=dict)  # crossing -> ped in the ego's lane
    done: bool = False
    pedestrians: PedestrianSource | None = None
    kerb: KerbYield = field(default_factory=KerbYield)
    amber: AmberDecision = field(default_factory=AmberDecision)
    noise: ObservationNoise = field(default_factory=ObservationNoise)
    noise_rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))
    lane_id: str | None = None  # the ego's lane, read where SUMO changes its lanes


class UrbanDriveEnv(gym.Env[NDArray[np.float32], np.int64]):
    """The paper's command-conditioned driving task in the urban scenario.

    Args:
        config: an :class:`EnvConfig` or a mapping of its fields (unknown keys rejected).
        render_mode: ``None`` (libsumo, headless) or ``"human"`` (sumo-gui over TraCI).
        **overrides: individual config fields, e.g. ``traffic_level=0.5``.

    Reset options: ``command`` (fast|comfort|stop), ``traffic_level``,
    ``command_schedule`` [(time_s, command), ...] and ``obs_noise`` (sd_m, sd_mps). See
    :mod:`explaindrive.env.state` for the observation, :mod:`explaindrive.env.reward` for the
    rewards and :mod:`explaindrive.env.noise` for the observation noise.
    """

    metadata = {"render_modes": ["human"], "render_fps": 1}  # noqa: RUF012

    def __init__(
        self,
        config: EnvConfig | Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        **overrides: Any,
    ) -> None:
        super().__init__()
        if render_mode not in (None, "human"):
            raise ValueError(f"render_mode must be None or 'human', got {render_mode!r}")
        if isinstance(config, EnvConfig):
            cfg = config.replace(**overrides) if overrides else config
        else:
            cfg = EnvConfig.from_mapping({**dict(config or {}), **overrides})
        self.config = cfg
        self.render_mode = render_mode
        self._scenarios = ScenarioSource(
            cfg.cache_dir or user_cache_dir(), cfg.scenario, cfg.net_file, cfg.route,
            cfg.demand_file, cfg.scenario_every, cfg.scenario_paper_share,
        )  # fmt: skip
        self.scenario: ScenarioFiles = self._scenarios.current
        self.geometry: RouteGeometry
        self._crossing_lanes: dict[str, CrossingLane]
        self._load_geometry(self.scenario)
        if cfg.normalize_obs:
            low, high = S.normalize(S.STATE_LOW), S.normalize(S.STATE_HIGH)
        else:
            low, high = S.STATE_LOW, S.STATE_HIGH
        self.observation_space = gym.spaces.Box(low=low, high=high, dtype=np.float32)
        self.action_space = gym.spaces.Discrete(N_ACTIONS)
        self._conn = SumoConnection(gui=render_mode == "human")
        self._ep: _Episode | None = None
        self._leader_len: dict[str, float] = {}
        self._tls_link: dict[str, int] = {}  # traffic light -> index of the ego's link
        self._ego_min_gap_m = 0.0  # SUMO reports leader gaps minus the ego's minGap
        self._ego_length_m = 0.0
        self._last_obs = np.zeros(S.STATE_DIM, dtype=np.float32)

    # ------------------------------------------------------------------ public API
    @property
    def command(self) -> Command:
        """The active passenger command."""
        return self._episode().command

    def set_command(self, command: str | int | Command) -> None:
        """Change the passenger command; it applies from the next action on.

        Raises:
            ValueError: for an unknown command.
        """
        cmd = Command.parse(command)
        ep = self._episode()
        ep.command = cmd
        self._last_obs[S.CMD] = float(cmd)

    @property
    def time_s(self) -> float:
        """Seconds since the ego entered."""
        return float(self._episode().steps) * STEP_LENGTH_S

    @property
    def route_pos_m(self) -> float:
        """The ego's front along its route [m] (the distances to lights and crossings are
        measured from it)."""
        return self._episode().pos_m

    @property
    def sumo(self) -> Any:
        """The running ``libsumo``/``traci`` module, for read-only inspection (e.g. rendering)."""
        return self._conn.api

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start an episode: warmed-up traffic (cached state), then the ego enters.

        The same ``seed`` (and traffic level) gives the same episode.
        """
        super().reset(seed=seed)
        opts = ResetOptions.parse(options)
        level = opts.traffic_level if opts.traffic_level is not None else self.config.traffic_level
        sumo_seed = seed if seed is not None else int(self.np_random.integers(0, SEED_LIMIT - 1))
        validate_seed(sumo_seed)
        self._use_scenario(self._scenarios.for_episode(int(sumo_seed)))
        try:
            self._conn.start_or_load(sumo_args(self.scenario, level, int(sumo_seed)))
            restore_warm_state(self._conn.api, self.scenario, level, int(sumo_seed),
                               self.config.warmup_s)  # fmt: skip
            start_pos = self._insert_ego(drop_backlog=level > SATURATED_LEVEL)
        except BaseException:
            self.close()
            raise
        schedule = list(opts.command_schedule)
        self._ep = _Episode(
            command=opts.command,
            schedule=schedule,
            start_pos_m=start_pos,
            pedestrians=PedestrianSource(int(sumo_seed), self.scenario.pedestrian_flows),
            amber=AmberDecision(always=self.config.yellow_leader == "always"),
            noise=opts.noise if opts.noise is not None else self.config.noise,
            noise_rng=np.random.default_rng([int(sumo_seed), 17]),
        )
        self._apply_schedule(0.0)
        self._ep.pos_m = start_pos
        api = self._conn.api
        obs, _leader, _ = self._observe(api, api.vehicle.getSubscriptionResults(EGO_ID))
        self._last_obs = obs
        info = {
            "scenario": self.scenario.name,
            "command": self._ep.command.label,
            "traffic_level": level,
            "seed": int(sumo_seed),
            "time_s": 0.0,
            "distance_m": 0.0,
        }
        if self._ep.noise.active:
            info["true_obs"] = obs.copy()
        return self._output(obs), info

    def step(
        self, action: int | np.integer[Any]
    ) -> tuple[NDArray[np.float32], float, bool, bool, dict[str, Any]]:
        """Apply a speed change for one 1 s step.

        Raises:
            ValueError: if ``action`` is outside ``Discrete(7)``.
            RuntimeError: if the episode is over (call ``reset``).
        """
        ep = self._episode()
        if ep.done:
            raise RuntimeError("the episode is over; call reset() before step()")
        change = speed_change(action)
        cmd, prev_obs, prev_pos = ep.command, self._last_obs, ep.pos_m
        motion = self._advance(ep, change)
        if self.config.ego_model != "agent":
            change = round(motion.speed_mps - ep.speed_mps)
        accel = motion.speed_mps - ep.speed_mps
        jerk = accel - ep.accel_mps2
        # violations are judged on what the ego saw before this step's observation
        red_run = self._ran_red_light(prev_pos, ep.pos_m)
        ped_violation = self._violated_crossing(prev_pos, ep.pos_m)
        ep.speed_mps, ep.accel_mps2 = motion.speed_mps, accel
        self._apply_schedule(ep.steps * STEP_LENGTH_S)
        obs, leader, real = self._next_observation(motion, prev_obs)
        step = _Step(
            command=cmd, change=change, accel=accel, jerk=jerk, motion=motion, leader=leader,
            real=real, limit_mps=float(prev_obs[S.V_LIM]), red_run=red_run,
            ped_violation=ped_violation,
        )  # fmt: skip
        terms = reward_terms(cmd, self._features(step), RECIPES[self.config.reward])
        terminated = motion.collided or motion.arrived
        truncated = not terminated and ep.steps >= self.config.max_steps
        ep.done = terminated or truncated
        self._last_obs = obs
        info = self._info(step, terms)
        if ep.noise.active:
            info["true_obs"] = obs.copy()
        return self._output(obs), terms.total, terminated, truncated, info

    # ------------------------------------------------------------------ step pieces
    def _advance(self, ep: _Episode, change: int) -> _Motion:
        """Set the ego's speed (or let SUMO drive it), simulate one step, read the outcome."""
        api = self._conn.api
        v_new = max(0.0, ep.speed_mps + change)
        try:
            if self.config.ego_model != "agent":
                # SUMO drives; STOP asks it to brake to a standstill within its decel limit.
                api.vehicle.setSpeed(EGO_ID, 0.0 if ep.command is Command.STOP else -1.0)
            else:
                api.vehicle.setSpeed(EGO_ID, v_new)
            if ep.pedestrians is not None:
                ep.pedestrians.step(api, ep.steps * STEP_LENGTH_S)
            v_next = v_new if self.config.ego_model == "agent" else ep.speed_mps
            reach = stopping_need(v_next)
            ep.kerb.update(api, self.geometry.crossings, ep.pos_m, self._ego_length_m, reach)
            api.simulationStep()
        except BaseException:
            self.close()
            raise
        ep.steps += 1
        sim = api.simulation.getSubscriptionResults()
        collided = bool(sim.get(tc.VAR_COLLIDING_VEHICLES_IDS)) and self._ego_collided()
        arrived = not collided and EGO_ID in sim.get(tc.VAR_ARRIVED_VEHICLES_IDS, ())
        ego = None
        if not collided and not arrived:
            ego = api.vehicle.getSubscriptionResults(EGO_ID)
        if ego is not None:
            v_new = float(ego[tc.VAR_SPEED])
            ep.pos_m = ep.start_pos_m + float(ego[tc.VAR_DISTANCE])
        else:
            ep.pos_m += v_new * STEP_LENGTH_S
        return _Motion(v_new, collided, arrived, ego)

    def _next_observation(
        self, motion: _Motion, prev_obs: NDArray[np.float32]
    ) -> tuple[NDArray[np.float32], _Leader | None, _Leader | None]:
        """Observation after the step with its effective and real leaders; once the ego has
        left the simulation, the previous observation with the new speed and command."""
        if motion.ego is not None:
            return self._observe(self._conn.api, motion.ego)
        obs = prev_obs.copy()
        obs[S.V_EGO] = motion.speed_mps
        obs[S.CMD] = float(self._episode().command)
        return obs, None, None

    @staticmethod
    def _features(step: _Step) -> StepFeatures:
        """What the reward needs, w.r.t. the effective (real or virtual) leader."""
        leader, v = step.leader, step.motion.speed_mps
        stop_reason: str | None = None
        if leader is not None and leader.gap_m <= STOP_REASON_GAP_M:
            stop_reason = "signal" if leader.virtual else "queue"
        real = step.real
        return StepFeatures(
            speed_mps=v,
            speed_change_mps=step.change,
            limit_mps=step.limit_mps,
            ttc_s=step.ttc_s,
            headway_s=time_headway(leader.gap_m, leader.length_m, v) if leader else math.inf,
            jerk_mps3=step.jerk,
            violation=step.red_run or step.ped_violation,
            stop_reason=stop_reason,
            collided=step.motion.collided,
            real_headway_s=time_headway(real.gap_m, real.length_m, v) if real else math.inf,
            accel_mps2=step.accel,
            leader_gap_m=leader.gap_m if leader else math.inf,
            closing_speed_mps=v - leader.speed_mps if leader else 0.0,
        )

    def _info(self, step: _Step, terms: RewardTerms) -> dict[str, Any]:
        """The step's ``info``: command, kinematics, leaders, safety events, reward terms."""
        ep = self._episode()
        v, leader, real = step.motion.speed_mps, step.leader, step.real
        legal_limit = self.geometry.limit_at(ep.pos_m)
        return {
            "command": step.command.label,
            "next_command": ep.command.label,
            "time_s": ep.steps * STEP_LENGTH_S,
            "speed_mps": v,
            "speed_change_mps": step.change,
            "accel_mps2": step.accel,
            "jerk_mps3": step.jerk,
            "limit_mps": legal_limit,
            "posted_limit_mps": step.limit_mps,
            "gap_m": leader.gap_m if leader else math.inf,
            "leader_virtual": bool(leader.virtual) if leader else False,
            "ttc_s": step.ttc_s,
            "headway_s": time_headway(leader.gap_m, leader.length_m, v) if leader else math.inf,
            "real_gap_m": real.gap_m if real else math.inf,
            "real_ttc_s": time_to_collision(real.gap_m, v - real.speed_mps) if real else math.inf,
            "real_headway_s": time_headway(real.gap_m, real.length_m, v) if real else math.inf,
            "real_leader_speed_mps": real.speed_mps if real else math.inf,
            "light_gap_m": float(self._last_obs[S.D_TL]),
            "light_state": S.LightState(int(self._last_obs[S.TLS])).label,
            "crossing_gap_m": float(self._last_obs[S.D_CROSS]),
            "distance_m": ep.pos_m - ep.start_pos_m,
            "collision": step.motion.collided,
            "red_light_run": step.red_run,
            "ped_violation": step.ped_violation,
            "speeding": v > legal_limit + 1e-6,
            "arrived": step.motion.arrived,
            "reward_terms": terms.as_dict(),
        }

    def close(self) -> None:
        """Stop SUMO (idempotent)."""
        self._conn.close()
        self._ep = None

    # ------------------------------------------------------------------ SUMO plumbing
    def _episode(self) -> _Episode:
        if self._ep is None:
            raise RuntimeError("no episode is running; call reset() first")
        return self._ep

    def _load_geometry(self, scenario: ScenarioFiles) -> None:
        """The route's geometry and the ego lane's stretch on each of its crossings."""
        self.geometry = load_route_geometry(scenario.net_file, scenario.route_edges)
        self._crossing_lanes = crossing_lanes(
            scenario.net_file, {c.crossing_edge: c.approach_edge for c in self.geometry.crossings}
        )

    def _use_scenario(self, scenario: ScenarioFiles) -> None:
        """Drive the next episodes in ``scenario`` (a new draw under domain randomisation)."""
        if scenario is self.scenario:
            return
        self.scenario = scenario
        self._load_geometry(scenario)
        self._tls_link = {}
        self._conn.close()  # the next episode starts SUMO on the new network

    def _insert_ego(self, drop_backlog: bool = False) -> float:
        api = self._conn.api
        model = self.config.ego_model
        type_id = EGO_TYPE_ID if model == "agent" else BASELINE_EGO_TYPES[model]
        api.vehicle.add(
            EGO_ID,
            EGO_ROUTE_ID,
            typeID=type_id,
            depart="now",
            departLane="best",
            departPos="base",
            departSpeed="0",
        )
        for waited in range(self.config.insert_timeout_s):
            api.simulationStep()
            if EGO_ID in api.simulation.getDepartedIDList():
                break
            if waited and waited % ENTRY_CLEAR_AFTER_S == 0:
                self._clear_entry(drop_backlog or waited >= BACKLOG_DROP_AFTER_S)
        else:
            raise RuntimeError(
                f"the ego could not enter within {self.config.insert_timeout_s} s "
                "(the first road stays blocked); lower the traffic level"
            )
        lane_changes = STRATEGIC_LANE_CHANGES if self.scenario.strategic_lane_changes else 0
        api.vehicle.setLaneChangeMode(EGO_ID, lane_changes)
        self._ego_min_gap_m = float(api.vehicle.getMinGap(EGO_ID))
        self._ego_length_m = float(api.vehicle.getLength(EGO_ID))
        if model == "agent":
            api.vehicle.setSpeedMode(EGO_ID, 0)  # no car-following, light or right-of-way checks
            api.vehicle.setSpeed(EGO_ID, 0.0)
        ego_vars = _EGO_LANE_VARS if self.scenario.strategic_lane_changes else _EGO_VARS
        api.vehicle.subscribe(EGO_ID, ego_vars, parameters={tc.VAR_LEADER: S.SENSOR_RANGE_M})
        if not self._tls_link:
            self._tls_link = {t[0]: int(t[1]) for t in api.vehicle.getNextTLS(EGO_ID)}
        for tls_id in self._tls_link:
            api.trafficlight.subscribe(tls_id, (tc.TL_RED_YELLOW_GREEN_STATE,))
        api.simulation.subscribe(_SIM_VARS)
        for crossing in self.geometry.crossings:
            for edge in (crossing.crossing_edge, *crossing.walkingareas):
                api.edge.subscribe(edge, (tc.LAST_STEP_PERSON_ID_LIST,))
        return float(api.vehicle.getLanePosition(EGO_ID))

    def _clear_entry(self, drop_backlog: bool) -> None:
        """Remove background vehicles from the ego's entry stretch (oversaturated demand), and
        with ``drop_backlog`` those still waiting to enter there, which SUMO would insert
        before the ego."""
        api = self._conn.api
        edge = self.scenario.route_edges[0]
        if drop_backlog:
            for vid in api.simulation.getPendingVehicles():
                if vid != EGO_ID and api.vehicle.getRoute(vid)[0] == edge:
                    api.vehicle.remove(vid)
        lanes = [f"{edge}_{i}" for i in range(api.edge.getLaneNumber(edge))]
        for vid in (v for lane in lanes for v in api.lane.getLastStepVehicleIDs(lane)):
            if vid != EGO_ID and api.vehicle.getLanePosition(vid) < ENTRY_CLEAR_M:
                api.vehicle.remove(vid)
        log.debug("cleared the ego's entry stretch after %d s without a gap", ENTRY_CLEAR_AFTER_S)

    def _apply_schedule(self, now_s: float) -> None:
        ep = self._episode()
        while ep.schedule and ep.schedule[0][0] <= now_s + 1e-9:
            ep.command = ep.schedule.pop(0)[1]

    def _ego_collided(self) -> bool:
        for col in self._conn.api.simulation.getCollisions():
            if EGO_ID in (col.collider, col.victim):
                return True
        return False

    # ------------------------------------------------------------------ perception
    def _persons(self, edge: str) -> tuple[str, ...]:
        res = self._conn.api.edge.getSubscriptionResults(edge)
        return tuple(res.get(tc.LAST_STEP_PERSON_ID_LIST, ()))

    def _crossing_occupied(
        self, crossing: RouteCrossing, on_it: bool, judge: bool = True
    ) -> tuple[bool, bool]:
        """(busy, in_lane): a pedestrian is on the crossing or, at a zebra, about to
        step onto it; and whether one is in, or stepping into, the ego's lane on it
        (looked at only with ``judge``: the ego is close enough to cross the line next).

        At a signalized crossing pedestrians waiting on the kerb wait for their own
        green, and once the ego is on the crossing (``on_it``) those on the kerb wait for
        it, so then only pedestrians already on the crossing count. At a zebra, those
        waiting for the ego (:class:`~explaindrive.sim.pedestrians.KerbYield`) do not.
        """
        on_crossing = self._persons(crossing.crossing_edge)
        if on_crossing:
            return True, judge and self._in_lane(crossing, on_crossing)
        if crossing.signalized or on_it:
            return False, False
        person, ep = self._conn.api.person, self._episode()
        entering = tuple(
            pid
            for wa in crossing.walkingareas
            for pid in self._persons(wa)
            if person.getNextEdge(pid) == crossing.crossing_edge and not ep.kerb.holds(pid)
        )
        return bool(entering), judge and bool(entering) and self._in_lane(crossing, entering)

    def _in_lane(self, crossing: RouteCrossing, persons: tuple[str, ...]) -> bool:
        """Whether one of ``persons`` is in, or stepping into, the ego's lane on the crossing."""
        lane = self._crossing_lanes[crossing.crossing_edge]
        return any(pedestrian_in_lane(self._conn.api, lane, pid) for pid in persons)

    def _observe(
        self, api: Any, ego: Any
    ) -> tuple[NDArray[np.float32], _Leader | None, _Leader | None]:
        """Observation, effective leader (real or virtual) and real leader.

        ``ego`` is the ego's subscription result of the current step. The effective leader
        is the nearest of the real leader, a red or yellow light's stop line and an
        occupied crossing.
        """
        ep = self._episode()
        v = float(ego[tc.VAR_SPEED])
        ep.lane_id = ego.get(tc.VAR_LANE_ID)
        rng = S.SENSOR_RANGE_M
        real = self._real_leader(api, ego)
        leader = real
        d_tl, tls, light_id = self._next_light(api, ep.pos_m)
        if ep.amber.is_leader(light_id, tls, v, d_tl) and (leader is None or d_tl < leader.gap_m):
            leader = _Leader(max(d_tl, 0.0), 0.0, 0.0, True)
        d_cross = self._next_busy_crossing(ep.pos_m)
        if d_cross < rng and (leader is None or d_cross < leader.gap_m):
            leader = _Leader(d_cross, 0.0, 0.0, True)
        values = (
            float(ep.command),
            v,
            self.geometry.posted_limit(ep.pos_m),
            leader.gap_m if leader else rng,
            (v - leader.speed_mps) if leader else 0.0,
            d_tl,
            float(tls),
            d_cross,
        )
        # clipped in Python (the bounds are float32 values, so rounding afterwards gives
        # the same result as clipping the float32 array): cheaper than two numpy calls
        obs = np.array(
            [min(max(x, lo), hi) for x, lo, hi in zip(values, _LOW, _HIGH, strict=True)],
            dtype=np.float32,
        )
        return obs, leader, real

    def _real_leader(self, api: Any, ego: Any) -> _Leader | None:
        """The vehicle ahead in the ego's lane within sensor range (bumper-to-bumper gap)."""
        lead = ego.get(tc.VAR_LEADER)
        gap = float(lead[1]) + self._ego_min_gap_m if lead and lead[0] else S.SENSOR_RANGE_M
        if gap >= S.SENSOR_RANGE_M:
            return None
        lid = lead[0]
        length = self._leader_len.get(lid)
        if length is None:
            length = self._leader_len[lid] = float(api.vehicle.getLength(lid))
        return _Leader(max(gap, 0.0), float(api.vehicle.getSpeed(lid)), length, False)

    def _next_light(self, api: Any, pos: float) -> tuple[float, S.LightState, str | None]:
        """Distance to the next light's stop line, its colour and its id (range, green and
        ``None`` when none is in range); records the colours the ego's lights show."""
        ep = self._episode()
        d_tl, tls, light_id = S.SENSOR_RANGE_M, S.LightState.GREEN, None
        ep.light_state = {}
        for light in self.geometry.lights:
            ahead = light.stop_line_m - pos
            if ahead < 0.0 or light.tls_id not in self._tls_link:
                continue
            states = api.trafficlight.getSubscriptionResults(light.tls_id)
            colour = S.LightState.from_sumo(states[tc.TL_RED_YELLOW_GREEN_STATE][self._link(light)])
            ep.light_state[light.tls_id] = colour
            if ahead < S.SENSOR_RANGE_M:
                d_tl, tls, light_id = ahead, colour, light.tls_id
            break
        return d_tl, tls, light_id

    def _link(self, light: RouteLight) -> int:
        """The ego's link at ``light``: the one from the lane it is on when that lane
        approaches the light, else the one it was routed through at entry."""
        lane = self._episode().lane_id
        index = light.link_of(lane) if lane is not None else None
        return self._tls_link[light.tls_id] if index is None else index

    def _next_busy_crossing(self, pos: float) -> float:
        """Distance to the nearest crossing a pedestrian is on or entering (range if none);
        records which crossings have a pedestrian on them."""
        ep = self._episode()
        d_cross = S.SENSOR_RANGE_M
        ep.occupied = {}
        for crossing in self.geometry.crossings:
            ahead = crossing.stop_line_m - pos
            # Relevant from sensor range until the ego's front has left the junction: a car
            # stopped on the crossing (e.g. by a STOP command) must not roll into pedestrians.
            if crossing.stop_line_m - crossing.end_m <= ahead < S.SENSOR_RANGE_M:
                busy, in_lane = self._crossing_occupied(
                    crossing, on_it=ahead < 0.0, judge=ahead < JUDGE_CROSSING_M
                )
                ep.occupied[crossing.crossing_edge] = in_lane
                if busy:
                    d_cross = min(d_cross, max(ahead, 0.0))
        return d_cross

    def _ran_red_light(self, prev_pos: float, pos: float) -> bool:
        """The ego's front crossed a stop line during this step while the light was red.

        SUMO switches signals at the start of a step and then moves the cars, so the
        colour read after the step is the one that held while the ego crossed.
        """
        for light in self.geometry.lights:
            if prev_pos < light.stop_line_m <= pos and light.tls_id in self._tls_link:
                states = self._conn.api.trafficlight.getSubscriptionResults(light.tls_id)
                char = states[tc.TL_RED_YELLOW_GREEN_STATE][self._link(light)]
                return S.LightState.from_sumo(char) is S.LightState.RED
        return False

    def _violated_crossing(self, prev_pos: float, pos: float) -> bool:
        """The ego's front crossed a crossing's stop line during this step while a
        pedestrian was in, or stepping into, its lane (before or after the step)."""
        ep = self._episode()
        for crossing in self.geometry.crossings:
            if prev_pos < crossing.stop_line_m <= pos:
                was = ep.occupied.get(crossing.crossing_edge, False)
                on_crossing = self._persons(crossing.crossing_edge)
                return was or (bool(on_crossing) and self._in_lane(crossing, on_crossing))
        return False

    def _output(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        """What the driver sees: the observation with the episode's sensor noise."""
        ep = self._ep
        seen = ep.noise.apply(obs, ep.noise_rng) if ep is not None else obs.copy()
        return S.normalize(seen) if self.config.normalize_obs else seen
