"""Typed, validated request bodies of the web API (unknown fields are rejected)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator

from explaindrive.config import LaxModel, Seed, TrafficLevel
from explaindrive.ride.config import RideConfig

MAX_TEXT_CHARS = 300  # a spoken request is a sentence or two
MAX_RIDE_STEPS = 1800  # [s] half an hour of driving


class StartRequest(LaxModel):
    """Start a new ride.

    Attributes:
        traffic_level: demand scale, in (0, ``MAX_TRAFFIC_LEVEL``]
            (1.0 = 900 veh/h on the main road).
        seed: simulation seed; the same seed and level give the same traffic.
        command: the command the car starts with.
        max_steps: longest ride [s].
    """

    traffic_level: TrafficLevel = RideConfig.model_fields["traffic_level"].default
    seed: Seed = RideConfig.model_fields["seed"].default
    command: Literal["fast", "comfort", "stop"] = "comfort"
    max_steps: int = Field(
        default=RideConfig.model_fields["max_steps"].default, gt=0, le=MAX_RIDE_STEPS
    )


class SayRequest(LaxModel):
    """A typed passenger line.

    Attributes:
        text: what the passenger says (surrounding white space is removed).
    """

    text: str = Field(min_length=1, max_length=MAX_TEXT_CHARS)

    @field_validator("text")
    @classmethod
    def _not_blank(cls, value: str) -> str:
        value = value.strip()
        if not value:
            raise ValueError("text must not be blank")
        return value


class AnswerRequest(LaxModel):
    """The passenger's answer to the confirmation question.

    Attributes:
        yes: ``true`` confirms the reformulated request, ``false`` cancels it.
    """

    yes: bool
