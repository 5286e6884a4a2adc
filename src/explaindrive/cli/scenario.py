"""``explaindrive scenario build|plot``: regenerate the network and its figure."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console

from explaindrive.cli._errors import error_line
from explaindrive.cli._paths import refuse_bad_outputs
from explaindrive.sim.scenario.files import package_data_dir

scenario_app = typer.Typer(help="Build or draw the urban SUMO scenario.", no_args_is_help=True)


@scenario_app.command("build")
def build(
    out: Path = typer.Option(None, help="Output directory (default: the package's scenario data)."),
) -> None:
    """Write the plain XML and run netconvert to produce urban.net.xml."""
    from explaindrive.sim.scenario.build import build_network

    refuse_bad_outputs(folders=((out, "--out"),))
    net = build_network(out or package_data_dir())
    Console().print(f"network written to {net}")


@scenario_app.command("plot")
def plot(
    out: Path = typer.Option(Path("docs/network.png"), help="PNG file to write."),
    net: Path = typer.Option(None, help="Network file (default: the shipped scenario)."),
) -> None:
    """Draw the network to a PNG."""
    from explaindrive.sim.scenario.plot import plot_network

    refuse_bad_outputs(files=((out, "--out"),))
    net_file = net or package_data_dir() / "urban.net.xml"
    if not net_file.is_file():
        Console().print(error_line(f"network file not found: {net_file}"))
        raise typer.Exit(2)
    Console().print(f"figure written to {plot_network(net_file, out)}")


def register(app: typer.Typer) -> None:
    """Add the command group to the CLI."""
    app.add_typer(scenario_app, name="scenario")
