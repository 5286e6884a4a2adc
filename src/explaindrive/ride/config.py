"""Typed settings of a ride."""

from __future__ import annotations

from typing import Annotated

from pydantic import AfterValidator, Field, NonNegativeFloat, PositiveInt

from explaindrive.config import ConfigModel, Seed, TextPath, TrafficLevel
from explaindrive.env.noise import NoiseSD
from explaindrive.language.backends import check_backend
from explaindrive.limits import COOLDOWN_LIMIT, STEP_LIMIT
from explaindrive.sim.scenario.choice import ScenarioFields


class RideConfig(ConfigModel, ScenarioFields):
    """Settings of :class:`~explaindrive.ride.session.RideSession`.

    Attributes:
        traffic_level: demand scale, in (0, ``MAX_TRAFFIC_LEVEL``]
            (1.0 = 900 veh/h on the main road).
        seed: simulation seed.
        max_steps: longest ride [steps of 1 s].
        backend: language backend (``embedded`` or ``openai``).
        auto_confirm: answer every confirmation question with yes.
        stop_without_confirm: apply a STOP request as soon as it is understood.
        explanation_cooldown_s: an explanation for the same reason is repeated only
            after this long [s]; a new reason is explained at once.
        interpret_deadline_s: wall-time budget of interpreting a typed request [s]: a
            request that is not a STOP may wait this long for its confirmation question
            (STOP is read offline first and keeps its bound).
        audio_deadline_s: wall-time budget of transcribing and interpreting a spoken
            request [s] (Whisper on a CPU needs about half the clip's length).
        decide_deadline_s: wall-time budget of one LLM-2 decision [s]. Decisions run
            ahead of the driving loop: a step whose decision would wait behind a busy
            model goes without one (the ride's history carries what it saw).
        explain_deadline_s: wall-time budget of one LLM-3 explanation [s]; an explanation
            that arrives after its step is shown if its cause is still present.

        The three defaults (4 s) let a model that answers in 1-3 s be used: a remote
        model's own deadline (``openai.timeout_s``, 3 s by default) plus the embedded
        fallback's margin must fit each of them.
        realtime: pace the ride at one step per second.
        gui: show the ride in sumo-gui.
        fast_policy: the fast network ``explaindrive ride`` loads instead of the shipped
            one (a policy ``.pt`` file or a training run directory); kept in the summary.
        comfort_policy: likewise for the comfort network.
        obs_noise: ``(sd_m, sd_mps)``: sensor noise on what the driver sees
            (:mod:`explaindrive.env.noise`).
    """

    config_name = "ride config"

    traffic_level: TrafficLevel = 1.0
    seed: Seed = 0
    max_steps: Annotated[PositiveInt, STEP_LIMIT] = 600  # at most 7,200
    backend: Annotated[str, AfterValidator(check_backend)] = "embedded"
    auto_confirm: bool = False
    stop_without_confirm: bool = False
    explanation_cooldown_s: Annotated[NonNegativeFloat, COOLDOWN_LIMIT] = 15.0  # <= 3,600
    interpret_deadline_s: NonNegativeFloat = 4.0
    audio_deadline_s: NonNegativeFloat = 8.0
    decide_deadline_s: NonNegativeFloat = 4.0
    explain_deadline_s: NonNegativeFloat = 4.0
    realtime: bool = False
    gui: bool = False
    fast_policy: TextPath | None = None
    comfort_policy: TextPath | None = None
    obs_noise: NoiseSD = Field(default=(0.0, 0.0))
