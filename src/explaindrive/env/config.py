"""Typed configuration of the driving environment."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any

from pydantic import Field, NonNegativeInt, PositiveInt

from explaindrive import limits
from explaindrive.config import ConfigModel, TextPath, TrafficLevel, one_of
from explaindrive.env.lights import DEFAULT_YELLOW_LEADER, YELLOW_LEADERS
from explaindrive.env.noise import NoiseSD, ObservationNoise
from explaindrive.env.reward import REWARD_NAMES, StopWindow
from explaindrive.sim.scenario.choice import ScenarioFields

EGO_MODELS: tuple[str, ...] = ("agent", "krauss", "idm")


class EnvConfig(ConfigModel, ScenarioFields):
    """Settings of :class:`~explaindrive.env.urban_drive.UrbanDriveEnv`.

    Attributes:
        traffic_level: demand scale; 1.0 = 900 veh/h on the ego's main road.
        max_steps: step limit of an episode (truncation) [steps of 1 s].
        warmup_s: simulated time before the ego enters [s]; the state is cached.
        normalize_obs: return observations scaled into [-1, 1] (see ``env.state``).
        scenario, scenario_every, net_file, route, demand_file: where the ego drives
            (:class:`~explaindrive.sim.scenario.choice.ScenarioFields`).
        cache_dir: where generated demand files and warm-up states are kept.
        insert_timeout_s: how long the ego may wait for space to enter [s].
        ego_model: ``"agent"`` (the action sets the speed, SUMO's checks off) or a SUMO
            baseline that drives the ego itself with its safety checks on: ``"krauss"``
            or ``"idm"``. Baselines ignore the action; a STOP command makes SUMO brake to
            a standstill (at most 3 m/s^2) and hold it.
        yellow_leader: when a yellow light's stop line is a virtual leader: ``"decided"``
            once, when the ego first sees the yellow, by whether it can still stop there
            (:mod:`explaindrive.env.lights`), ``"gentle"`` (stop where braking by 2 m/s
            per step will do, or where the car could not clear the line in 2 s), or
            ``"always"``, as in the paper.
        reward: the reward recipe, ``"paper"`` or ``"passenger"``
            (:mod:`explaindrive.env.reward`).
        obs_noise: ``(sd_m, sd_mps)`` of the Gaussian noise on the observed distances and
            speeds (:mod:`explaindrive.env.noise`); violations and rewards are judged on
            the true state, which ``info["true_obs"]`` holds when noise is on.
        stop_window_m: ``(min, max)`` metres before the line within which the reward pays
            standing for a light or a pedestrian; ``None``: the recipe's own.
        speed_limiter: the speed limiter (Intelligent Speed Assistance) is on: a speed rise
            that would pass the posted limit lands on it
            (:func:`~explaindrive.env.actions.limited_speed`); the ``passenger`` preset's.
            Speeding is still judged on the true speed.
    """

    config_name = "env config"

    traffic_level: TrafficLevel = 1.0
    max_steps: Annotated[PositiveInt, limits.STEP_LIMIT] = 1000  # at most 7,200
    warmup_s: NonNegativeInt = 180
    normalize_obs: bool = False
    cache_dir: TextPath | None = None
    insert_timeout_s: PositiveInt = 60
    ego_model: Annotated[str, one_of(EGO_MODELS)] = "agent"
    yellow_leader: Annotated[str, one_of(YELLOW_LEADERS)] = DEFAULT_YELLOW_LEADER
    reward: Annotated[str, one_of(REWARD_NAMES)] = "paper"
    obs_noise: NoiseSD = Field(default=(0.0, 0.0))
    stop_window_m: StopWindow | None = None
    speed_limiter: bool = False

    @property
    def noise(self) -> ObservationNoise:
        """The observation noise as an :class:`ObservationNoise`."""
        return ObservationNoise(*self.obs_noise)

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> EnvConfig:
        """Build a config from a mapping, rejecting unknown keys (as :meth:`from_dict`).

        Raises:
            ConfigError: naming every unknown key and every invalid value.
        """
        return cls.from_dict(data)
