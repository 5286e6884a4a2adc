"""``explaindrive/UrbanDrive-v0``: longitudinal control of the ego car in the urban SUMO scenario.

Each step is 1 s. The action changes the ego speed by -3..+3 m/s; SUMO's own
safety checks for the ego are off (speed mode 0), so collisions, red-light runs,
pedestrian-yield and speed-limit violations can happen and are counted.

In the ``passenger`` preset the speed limiter is on (``speed_limiter``,
:func:`~explaindrive.env.actions.limited_speed`): a rise that would pass the posted limit
lands on it. ``change`` in the step's record stays the action's; the acceleration is the
speed's true change.

The environment composes small parts: :mod:`~explaindrive.env.sumo_process` (SUMO, the
warm-up, the ego's entry), :mod:`~explaindrive.env.perception` (the observation) and
:mod:`~explaindrive.env.violations` (what the ego did wrong).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
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
    least_stopping_need,
    limited_change,
    limited_speed,
    speed_change,
    stopping_need,
)
from explaindrive.env.config import EnvConfig
from explaindrive.env.episode import Episode, StepRecord
from explaindrive.env.lights import AmberDecision
from explaindrive.env.odometer import RouteOdometer
from explaindrive.env.options import ResetOptions
from explaindrive.env.perception import LeaderSensor, Percept, Perception
from explaindrive.env.render import TopDownView
from explaindrive.env.reward import RECIPES, RewardTerms, StepFeatures, reward_terms
from explaindrive.env.ride_quality import free_road
from explaindrive.env.safety import runtime_mask
from explaindrive.env.sumo_process import SUMO_DRIVES, EgoEntry, Motion, SumoProcess
from explaindrive.env.violations import ViolationJudge
from explaindrive.sim.crossing_lanes import CrossingLane, crossing_lanes
from explaindrive.sim.pedestrians import PedestrianSource
from explaindrive.sim.route import RouteGeometry, load_route_geometry, read_net
from explaindrive.sim.scenario.files import ScenarioFiles
from explaindrive.sim.scenario.limits import SATURATED_LEVEL, SEED_LIMIT, validate_seed
from explaindrive.sim.scenario.source import ScenarioSource


class UrbanDriveEnv(gym.Env[NDArray[np.float32], np.int64]):
    """The paper's command-conditioned driving task in the urban scenario.

    Args:
        config: an :class:`EnvConfig` or a mapping of its fields (unknown keys rejected).
        render_mode: ``None`` (libsumo, headless), ``"rgb_array"`` (libsumo; :meth:`render`
            returns a top-down view as an ``(H, W, 3)`` uint8 array) or ``"human"`` (sumo-gui
            over TraCI draws every step).
        **overrides: individual config fields, e.g. ``traffic_level=0.5``.

    Reset options: ``command`` (fast|comfort|stop), ``traffic_level``,
    ``command_schedule`` [(time_s, command), ...] and ``obs_noise`` (sd_m, sd_mps). See
    :mod:`explaindrive.env.state` for the observation, :mod:`explaindrive.env.reward` for the
    rewards and :mod:`explaindrive.env.noise` for the observation noise.

    ``info["action_mask"]`` after ``reset`` and ``step``, and :meth:`action_masks` at any
    time, give the 7 actions the run-time shield allows in the true state
    (:func:`explaindrive.env.safety.runtime_mask`), as masked-action learners expect.
    ``info["yield_gap_m"]`` after ``reset`` and ``step`` is the gap to the yield line where
    the ego must give way, held as a virtual leader in the observation returned with it
    (:mod:`explaindrive.env.right_of_way`; the sensor range, 200 m: none).
    """

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 1}  # noqa: RUF012

    def __init__(
        self,
        config: EnvConfig | Mapping[str, Any] | None = None,
        render_mode: str | None = None,
        **overrides: Any,
    ) -> None:
        super().__init__()
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None, 'human' or 'rgb_array', got {render_mode!r}"
            )
        if isinstance(config, EnvConfig):
            cfg = config.replace(**overrides) if overrides else config
        else:
            cfg = EnvConfig.from_mapping({**dict(config or {}), **overrides})
        self.config = cfg
        recipe = RECIPES[cfg.reward]
        self.recipe = (
            recipe if cfg.stop_window_m is None else recipe.with_stop_window(cfg.stop_window_m)
        )
        self.render_mode = render_mode
        self._scenarios = ScenarioSource(
            cfg.cache_dir or user_cache_dir(), cfg.scenario, cfg.net_file, cfg.route,
            cfg.demand_file, cfg.scenario_every, cfg.scenario_paper_share,
        )  # fmt: skip
        self.scenario: ScenarioFiles = self._scenarios.current
        self.geometry: RouteGeometry
        self._crossing_lanes: dict[str, CrossingLane]
        self._unregulated: frozenset[str]  # the route's junctions without junction logic
        self._load_geometry(self.scenario)
        if cfg.normalize_obs:
            low, high = S.normalize(S.STATE_LOW), S.normalize(S.STATE_HIGH)
        else:
            low, high = S.STATE_LOW, S.STATE_HIGH
        self.observation_space = gym.spaces.Box(low=low, high=high, dtype=np.float32)
        self.action_space = gym.spaces.Discrete(N_ACTIONS)
        self._sumo = SumoProcess(render_mode == "human", cfg.ego_model, cfg.insert_timeout_s)
        self._ep: Episode | None = None
        self._entry: EgoEntry | None = None
        self._leader_lengths: dict[str, float] = {}  # vehicle id -> length [m]
        self._odometer = RouteOdometer(self.geometry, 0.0)
        self._last_obs = np.zeros(S.STATE_DIM, dtype=np.float32)
        self._view: TopDownView | None = None

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
        return self._episode().time_s

    @property
    def route_pos_m(self) -> float:
        """The ego's front along its route [m] (the distances to lights and crossings are
        measured from it)."""
        return self._episode().pos_m

    def action_masks(self) -> NDArray[np.bool_]:
        """The actions the run-time shield allows in the current true state (a copy, shape
        ``(7,)``): :func:`~explaindrive.env.safety.runtime_mask` of the raw observation
        without sensor noise, with the active command (through the speed limiter when it is
        on)."""
        return runtime_mask(self._last_obs, self.config.speed_limiter)

    @property
    def _ego_length_m(self) -> float:
        """The ego's length [m] as read from SUMO when it last entered (0 before)."""
        return self._entry.length_m if self._entry is not None else 0.0

    @property
    def sumo(self) -> Any:
        """The running ``libsumo``/``traci`` module, for read-only inspection (e.g. rendering)."""
        return self._sumo.api

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
            entry = self._sumo.start_episode(
                self.scenario, self.geometry.crossings, level, int(sumo_seed),
                self.config.warmup_s, drop_backlog=level > SATURATED_LEVEL,
            )  # fmt: skip
        except BaseException:
            self.close()
            raise
        self._entry = entry
        leaders = LeaderSensor(entry.min_gap_m, self._leader_lengths)
        perception = Perception(
            self.geometry, self._crossing_lanes, leaders, entry.length_m, self._unregulated
        )
        self._ep = ep = Episode(
            command=opts.command,
            schedule=list(opts.command_schedule),
            start_pos_m=entry.start_pos_m,
            perception=perception,
            judge=ViolationJudge(perception.crossings, self.geometry, entry.length_m),
            pedestrians=PedestrianSource(int(sumo_seed), self.scenario.pedestrian_flows),
            amber=AmberDecision.for_rule(self.config.yellow_leader),
            noise=opts.noise if opts.noise is not None else self.config.noise,
            noise_rng=np.random.default_rng([int(sumo_seed), 17]),
        )
        ep.apply_schedule()
        ep.pos_m = entry.start_pos_m
        self._odometer = RouteOdometer(self.geometry, entry.start_pos_m)
        ep.seen = self._perceive(self._sumo.ego_state())
        obs = self._last_obs = ep.seen.obs
        info = {
            "scenario": self.scenario.name,
            "command": ep.command.label,
            "traffic_level": level,
            "seed": int(sumo_seed),
            "time_s": 0.0,
            "distance_m": 0.0,
            "yield_gap_m": ep.yield_gap_m,
            "action_mask": self.action_masks(),
        }
        if ep.noise.active:
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
        action_change = speed_change(action)
        cmd, prev_obs, prev_pos, seen = ep.command, self._last_obs, ep.pos_m, ep.seen
        posted_limit_mps = float(prev_obs[S.V_LIM])
        limit = posted_limit_mps if self.config.speed_limiter else None
        change: float = limited_change(ep.speed_mps, action_change, limit)
        motion = self._advance(ep, action_change, posted_limit_mps)
        if self.config.ego_model != "agent":
            change = round(motion.speed_mps - ep.speed_mps)
        accel = motion.speed_mps - ep.speed_mps
        jerk = accel - ep.accel_mps2
        # violations are judged on what the ego saw before this step's observation
        assert seen is not None  # set by reset
        violations = ep.judge(self._sumo.api, prev_pos, ep.pos_m, seen.links,
                              seen.crossings.in_lane, seen.yields.conflicts)  # fmt: skip
        ep.speed_mps, ep.accel_mps2 = motion.speed_mps, accel
        ep.apply_schedule()
        obs, leader, real = self._next_observation(motion, prev_obs)
        step = StepRecord(
            command=cmd, change=change, accel=accel, jerk=jerk, motion=motion, leader=leader,
            real=real, limit_mps=float(prev_obs[S.V_LIM]), violations=violations,
            free_road=free_road(
                real.gap_m if real else math.inf, ep.light_colour is not S.LightState.GREEN,
                float(obs[S.D_TL]), float(obs[S.D_CROSS]),
            ),
        )  # fmt: skip
        features = step.features()
        terms = self._reward(cmd, features).as_dict()
        terminated = self._is_terminated(motion)
        truncated = self._is_truncated(terminated)
        ep.done = terminated or truncated
        self._last_obs = obs
        info = step.info(ep, obs, self.geometry.limit_at(ep.pos_m), features, terms)
        info["action_mask"] = self.action_masks()
        if ep.noise.active:
            info["true_obs"] = obs.copy()
        return self._output(obs), terms["total"], terminated, truncated, info

    def render(self) -> NDArray[np.uint8] | None:
        """Under ``render_mode="rgb_array"``, the top-down view around the ego
        (:mod:`explaindrive.env.render`); ``None`` otherwise (sumo-gui draws under
        ``"human"``).

        Raises:
            RuntimeError: if no episode is running.
        """
        if self.render_mode != "rgb_array":
            return None
        api = self._sumo.api if self._ep is not None else None
        if api is None:
            raise RuntimeError("no episode is running; call reset() first")
        if self._view is None or self._view.net_file != self.scenario.net_file:
            self._view = TopDownView(self.scenario.net_file)
        return self._view(api)

    def close(self) -> None:
        """Stop SUMO (idempotent)."""
        self._sumo.close()
        self._ep = None

    # ------------------------------------------------------------------ step pieces
    def _reward(self, command: Command, features: StepFeatures) -> RewardTerms:
        """A step's reward terms under ``command``, the one its action was taken in."""
        return reward_terms(command, features, self.recipe)

    def _is_terminated(self, motion: Motion) -> bool:
        """The episode ends in a terminal state: the ego collided or reached its route's end."""
        return motion.collided or motion.arrived

    def _is_truncated(self, terminated: bool) -> bool:
        """The step limit cut a non-terminal episode."""
        return not terminated and self._episode().steps >= self.config.max_steps

    def _advance(self, ep: Episode, change: int, posted_limit_mps: float) -> Motion:
        """Set the ego's speed (or let SUMO drive it), simulate one step, read the outcome.
        With the speed limiter on, the speed goes through it at ``posted_limit_mps`` (the
        limit the agent observed; :func:`~explaindrive.env.actions.limited_speed`)."""
        limit = posted_limit_mps if self.config.speed_limiter else None
        v_new = limited_speed(ep.speed_mps, change, limit)
        agent = self.config.ego_model == "agent"
        # a baseline: SUMO drives; STOP asks it to brake to a standstill within its decel limit
        sumo_speed = 0.0 if ep.command is Command.STOP else SUMO_DRIVES
        set_speed = v_new if agent else sumo_speed
        reach = stopping_need(v_new if agent else ep.speed_mps)
        length_m = self._ego_length_m

        def before_step(api: Any) -> None:
            if ep.pedestrians is not None:
                ep.pedestrians.step(api, ep.time_s)
            ep.kerb.update(api, self.geometry.crossings, ep.pos_m, length_m, reach)

        try:
            motion = self._sumo.advance(set_speed, v_new, before_step)
        except BaseException:
            self.close()
            raise
        ep.steps += 1
        if motion.ego is not None:
            ego = motion.ego
            ep.pos_m = self._odometer(
                self._sumo.api, str(ego[tc.VAR_LANE_ID]), float(ego[tc.VAR_LANEPOSITION]),
                float(ego[tc.VAR_DISTANCE]),
            )  # fmt: skip
        else:
            ep.pos_m += motion.speed_mps * STEP_LENGTH_S
        return motion

    def _perceive(self, ego: Any) -> Percept:
        """What the ego perceives now (``ego``: its subscription results).

        Pedestrians who reached a zebra's kerb during the step wait for a car that can no
        longer stand still before it even braking hardest; the kerb rule holds them before
        they are seen as stepping out (it ran before the step, when they were not yet there).
        """
        ep = self._episode()
        reach = least_stopping_need(ep.speed_mps)
        ep.kerb.update(self._sumo.api, self.geometry.crossings, ep.pos_m, self._ego_length_m, reach)
        return ep.perception(self._sumo.api, ego, ep.pos_m, ep.command, ep.amber, ep.kerb)

    def _next_observation(
        self, motion: Motion, prev_obs: NDArray[np.float32]
    ) -> tuple[NDArray[np.float32], Any, Any]:
        """Observation after the step with its effective and real leaders; once the ego has
        left the simulation, the previous observation with the new speed and command."""
        ep = self._episode()
        if motion.ego is not None:
            ep.seen = self._perceive(motion.ego)
            return ep.seen.obs, ep.seen.leader, ep.seen.real
        obs = prev_obs.copy()
        obs[S.V_EGO] = motion.speed_mps
        obs[S.CMD] = float(ep.command)
        return obs, None, None

    # ------------------------------------------------------------------ scenario
    def _episode(self) -> Episode:
        if self._ep is None:
            raise RuntimeError("no episode is running; call reset() first")
        return self._ep

    def _load_geometry(self, scenario: ScenarioFiles) -> None:
        """The route's geometry and the ego lane's stretch on each of its crossings."""
        net = read_net(scenario.net_file)
        self.geometry = load_route_geometry(scenario.net_file, scenario.route_edges, net)
        self._unregulated = frozenset(
            j.node_id
            for j in self.geometry.junctions
            if net.getNode(j.node_id).getType() == "unregulated"
        )
        self._crossing_lanes = crossing_lanes(
            scenario.net_file,
            {c.crossing_edge: c.approach_edge for c in self.geometry.crossings},
            net,
        )

    def _use_scenario(self, scenario: ScenarioFiles) -> None:
        """Drive the next episodes in ``scenario`` (a new draw under domain randomisation)."""
        if scenario is self.scenario:
            return
        self.scenario = scenario
        self._load_geometry(scenario)
        self._sumo.new_network()  # the next episode starts SUMO on the new network

    def _output(self, obs: NDArray[np.float32]) -> NDArray[np.float32]:
        """What the driver sees: the observation with the episode's sensor noise."""
        ep = self._ep
        if ep is not None and ep.noise.active:
            seen = ep.noise.apply(obs, ep.noise_rng)
        else:
            seen = obs.copy()
        return S.normalize(seen) if self.config.normalize_obs else seen
