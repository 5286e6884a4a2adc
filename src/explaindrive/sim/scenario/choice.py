"""The settings that choose a scenario, shared by the env, training and ride configs."""

from __future__ import annotations

from typing import Annotated, Any, Self

from pydantic import (
    Field,
    PositiveInt,
    SerializerFunctionWrapHandler,
    model_serializer,
    model_validator,
)

from explaindrive.config import FROM_LIST, StrictModel, TextPath

RANDOM = "random"
"""The scenario setting that draws generated scenarios during training."""


class ScenarioFields(StrictModel):
    """Where the ego drives: the paper's road (nothing set), a scenario directory, generated
    scenarios, or a network of your own.

    Attributes:
        scenario: a scenario directory (``explaindrive scenario build|random``), or
            ``"random"``: a new generated scenario every ``scenario_every`` episodes.
        scenario_every: episodes per drawn scenario under ``scenario="random"``.
        scenario_paper_share: under ``scenario="random"``, the share of the draws that are
            the paper's road instead of a generated scenario (decided by the episode seed).
        net_file: a SUMO network to use instead of the shipped scenario: with ``route``
            any network, else a build of the paper's road.
        route: ``(FROM_EDGE, TO_EDGE)``: the ego drives SUMO's route between them on
            ``net_file`` (see docs/scenario.md).
        demand_file: background traffic on ``net_file`` (a SUMO route file, scaled by the
            traffic level); without one, trips generated over the network.
    """

    scenario: str | None = None
    scenario_every: PositiveInt = 20
    scenario_paper_share: float = Field(default=0.0, ge=0.0, le=1.0)
    net_file: TextPath | None = None
    route: Annotated[tuple[str, str], FROM_LIST] | None = None
    demand_file: TextPath | None = None

    @model_validator(mode="after")
    def _check_scenario(self) -> Self:
        if self.scenario is not None and (self.net_file or self.route or self.demand_file):
            raise ValueError("give a scenario or a network (net_file/route/demand_file), not both")
        if self.scenario_paper_share > 0.0 and self.scenario != RANDOM:
            raise ValueError("scenario_paper_share needs scenario='random'")
        if self.route is not None and self.net_file is None:
            raise ValueError("route needs net_file, the network it runs on")
        if self.demand_file is not None and self.route is None:
            raise ValueError("demand_file needs route and net_file")
        return self

    @model_serializer(mode="wrap")
    def _drop_defaults(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """Leave the scenario settings at their defaults out of dumps and saved configs, so
        a config of the paper's road reads as it did before scenarios could be chosen."""
        data: dict[str, Any] = handler(self)
        for key in _SCENARIO_KEYS:
            if key in data and data[key] == ScenarioFields.model_fields[key].default:
                del data[key]
        return data

    def scenario_fields(self) -> dict[str, Any]:
        """The scenario settings that are set, as env config fields."""
        return {k: getattr(self, k) for k in _SCENARIO_KEYS if getattr(self, k) is not None}


_SCENARIO_KEYS = (
    "scenario",
    "scenario_every",
    "scenario_paper_share",
    "net_file",
    "route",
    "demand_file",
)
