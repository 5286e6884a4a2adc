"""``explaindrive scenario build|random|plot``: build scenarios of the family and draw them."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console

from explaindrive.cli._errors import print_error
from explaindrive.cli._paths import refuse_bad_outputs

scenario_app = typer.Typer(help="Build or draw urban SUMO scenarios.", no_args_is_help=True)


@scenario_app.command("build")
def build(
    out: Path = typer.Option(None, help="Output directory (default: the package's scenario data)."),
    settings: list[str] = typer.Option(
        None, "--set", help="A parameter: --set limit_kmh=40 --set j1.cycle_s=90 (repeatable)."
    ),
) -> None:
    """Build a scenario: the paper's road, or with --set a scenario of the family (its
    network, demand and scenario.yaml; see docs/scenario.md)."""
    from explaindrive.config import ConfigError
    from explaindrive.sim.scenario.build import build_network
    from explaindrive.sim.scenario.directory import write_scenario_dir
    from explaindrive.sim.scenario.params import ScenarioParams

    refuse_bad_outputs(folders=((out, "--out"),))
    if not settings:
        from explaindrive.sim.scenario.files import package_data_dir

        net = build_network(out or package_data_dir())
        Console().print(f"network written to {net}")
        return
    if out is None:
        print_error("--set needs --out DIR (the package's road stays)")
        raise typer.Exit(2)
    try:
        params = ScenarioParams.from_settings(settings)
    except ConfigError as exc:
        print_error(exc)
        raise typer.Exit(2) from None
    write_scenario_dir(out, params, out.name)
    Console().print(f"scenario written to {out}")


@scenario_app.command("random")
def random(
    seed: int = typer.Option(..., "--seed", help="Generator seed (the same seed, the same road)."),
    out: Path = typer.Option(..., "--out", help="Output directory."),
) -> None:
    """Build scenario SEED of the seeded generator (ranges in docs/scenario.md)."""
    from explaindrive.sim.scenario.directory import write_scenario_dir
    from explaindrive.sim.scenario.generator import random_params

    try:
        params = random_params(seed)
    except ValueError as exc:
        print_error(exc)
        raise typer.Exit(2) from None
    refuse_bad_outputs(folders=((out, "--out"),))
    write_scenario_dir(out, params, f"random-{seed}", seed)
    Console().print(f"scenario random-{seed} written to {out}")


@scenario_app.command("plot")
def plot(
    out: Path = typer.Option(Path("docs/network.png"), help="PNG file to write."),
    net: Path = typer.Option(None, help="Network file (default: the shipped scenario)."),
) -> None:
    """Draw the network to a PNG."""
    from explaindrive.sim.scenario.files import package_data_dir
    from explaindrive.sim.scenario.plot import plot_network

    refuse_bad_outputs(files=((out, "--out"),))
    net_file = net or package_data_dir() / "urban.net.xml"
    if not net_file.is_file():
        print_error(f"network file not found: {net_file}")
        raise typer.Exit(2)
    Console().print(f"figure written to {plot_network(net_file, out)}")


def register(app: typer.Typer) -> None:
    """Add the command group to the CLI."""
    app.add_typer(scenario_app, name="scenario")
