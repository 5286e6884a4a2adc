"""``--scenario``, ``--net``, ``--route`` and ``--demand``: where the ego drives, one place for
``train``, ``evaluate``, ``ride`` and ``serve``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

ScenarioOption = Annotated[
    str | None,
    typer.Option(
        "--scenario",
        help="A scenario directory (explaindrive scenario build|random); train also takes "
        "'random': a new generated scenario every --set scenario_every=K episodes.",
    ),
]
NetOption = Annotated[
    Path | None, typer.Option("--net", help="A SUMO network of your own (.net.xml); needs --route.")
]
RouteOption = Annotated[
    str | None,
    typer.Option("--route", help="FROM_EDGE,TO_EDGE: the ego's route on --net (SUMO's path)."),
]
DemandOption = Annotated[
    Path | None,
    typer.Option("--demand", help="Background traffic on --net (.rou.xml); default: random trips."),
]


class ScenarioChoiceError(ValueError):
    """Scenario options that cannot be used together or at all; the message names why."""


def scenario_fields(
    scenario: str | None,
    net: Path | None,
    route: str | None,
    demand: Path | None,
    allow_random: bool = False,
) -> dict[str, Any]:
    """Env config fields for the scenario options, checked (the network and route are read
    and the scenario directory loaded, so a bad one fails here with one line).

    Raises:
        ScenarioChoiceError: naming the problem.
    """
    from explaindrive.sim.network import NetworkError, parse_route
    from explaindrive.sim.scenario.directory import ScenarioDirError
    from explaindrive.sim.scenario.source import RANDOM

    if scenario is not None and (net or route or demand):
        raise ScenarioChoiceError("give --scenario or --net/--route, not both")
    if (net is None) != (route is None):
        raise ScenarioChoiceError("--net and --route go together (--route FROM_EDGE,TO_EDGE)")
    if demand is not None and net is None:
        raise ScenarioChoiceError("--demand needs --net and --route")
    if scenario == RANDOM and not allow_random:
        raise ScenarioChoiceError(
            "--scenario random draws scenarios while training; to evaluate on generated "
            "scenarios use --scenarios random:100-119"
        )
    fields: dict[str, Any] = {}
    try:
        if scenario is not None:
            fields["scenario"] = scenario
        elif net is not None and route is not None:
            fields.update(net_file=net, route=parse_route(route))
            if demand is not None:
                fields["demand_file"] = demand
        check_scenario(fields)
    except (NetworkError, ScenarioDirError) as exc:
        raise ScenarioChoiceError(str(exc)) from None
    return fields


def scenario_args(
    scenario: str | None, net: Path | None, route: str | None, demand: Path | None
) -> list[str]:
    """The scenario options again, for a child ``explaindrive`` command."""
    args: list[str] = []
    for flag, value in (("--scenario", scenario), ("--net", net), ("--route", route),
                        ("--demand", demand)):  # fmt: skip
        if value is not None:
            args += [flag, str(value)]
    return args


def net_of(fields: dict[str, Any]) -> Path | None:
    """The network file the fields drive on (``None``: the paper's road)."""
    if "net_file" in fields:
        return Path(fields["net_file"])
    if "scenario" in fields:
        from explaindrive.sim.scenario.build import NET_FILE

        return Path(fields["scenario"]) / NET_FILE
    return None


def check_scenario(fields: dict[str, Any]) -> None:
    """Load the scenario the fields choose (building or generating what it needs once).

    Raises:
        NetworkError, ScenarioDirError: naming what cannot be used.
    """
    from explaindrive.cache import cache_dir
    from explaindrive.sim.scenario.source import ScenarioSource

    if fields:
        ScenarioSource(cache_dir(), fields.get("scenario"), fields.get("net_file"),
                       fields.get("route"), fields.get("demand_file"))  # fmt: skip
