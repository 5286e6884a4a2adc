"""Typed settings of a ride."""

from __future__ import annotations

import math
from dataclasses import dataclass

from explaindrive.language.backends import check_backend
from explaindrive.sim.scenario.layout import validate_seed, validate_traffic_level


@dataclass(frozen=True, slots=True)
class RideConfig:
    """Settings of :class:`~explaindrive.ride.session.RideSession`.

    Attributes:
        traffic_level: demand scale, in (0, 1.75] (1.0 = 900 veh/h on the main road).
        seed: simulation seed.
        max_steps: longest ride [steps of 1 s].
        backend: language backend (``embedded`` or ``openai``).
        auto_confirm: answer every confirmation question with yes.
        stop_without_confirm: apply a STOP request as soon as it is understood.
        explanation_cooldown_s: an explanation for the same reason is repeated only
            after this long [s]; a new reason is explained at once.
        interpret_deadline_s: wall-time budget of interpreting a typed request [s].
        audio_deadline_s: wall-time budget of transcribing and interpreting a spoken
            request [s] (Whisper on a CPU needs about half the clip's length).
        explain_deadline_s: wall-time budget of one decision or explanation [s].
        realtime: pace the ride at one step per second.
        gui: show the ride in sumo-gui.
    """

    traffic_level: float = 1.0
    seed: int = 0
    max_steps: int = 600
    backend: str = "embedded"
    auto_confirm: bool = False
    stop_without_confirm: bool = False
    explanation_cooldown_s: float = 15.0
    interpret_deadline_s: float = 2.0
    audio_deadline_s: float = 8.0
    explain_deadline_s: float = 1.0
    realtime: bool = False
    gui: bool = False

    def __post_init__(self) -> None:
        validate_traffic_level(self.traffic_level)
        validate_seed(self.seed)
        if self.max_steps <= 0:
            raise ValueError(f"max_steps must be > 0, got {self.max_steps}")
        for name in (
            "explanation_cooldown_s",
            "interpret_deadline_s",
            "audio_deadline_s",
            "explain_deadline_s",
        ):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {value}")
        check_backend(self.backend)
