"""``explaindrive serve``: the passenger web interface (limits: :mod:`explaindrive.web.server`)."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.console import Console

from explaindrive.cli import _scenario_options as where
from explaindrive.cli._errors import print_error
from explaindrive.cli._grid_options import ComfortPolicyOption, FastPolicyOption
from explaindrive.cli._language_common import CONFIG_HELP, MODEL_HELP, read_config

console = Console()


def serve(
    host: str = typer.Option(
        "127.0.0.1", "--host", help="Address to bind (local only by default)."
    ),
    port: int = typer.Option(8000, "--port", min=1, max=65535, help="TCP port."),
    backend: str | None = typer.Option(
        None, "--backend", help="Language backend: embedded or openai (default: --config's)."
    ),
    step_period: float = typer.Option(
        1.0,
        "--step-period",
        min=0.05,
        max=10.0,
        help="Seconds of wall time per 1 s control step (1 = real time).",
    ),
    allow_host: list[str] = typer.Option(
        [],
        "--allow-host",
        help="Another name the page is opened under (repeatable; e.g. the machine's LAN name).",
    ),
    fast_policy: FastPolicyOption = None,
    comfort_policy: ComfortPolicyOption = None,
    scenario: where.ScenarioOption = None,
    net: where.NetOption = None,
    route: where.RouteOption = None,
    demand: where.DemandOption = None,
    language: Path | None = typer.Option(None, "--config", help=CONFIG_HELP),
    model: str | None = typer.Option(None, "--model", help=MODEL_HELP),
) -> None:
    """Serve the passenger page: watch the ride, talk to the car, read its explanations."""
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.agent.controller import MergedController
    from explaindrive.language.backends import check_backend
    from explaindrive.language.intent.encoders import check_installed
    from explaindrive.web import create_app
    from explaindrive.web.app import RealStack
    from explaindrive.web.guard import LOOPBACK_HOSTS, served_hosts
    from explaindrive.web.server import run_server

    try:  # before the server starts
        language_config = read_config(language, model)
        backend = check_backend(backend or language_config.backend)
        check_installed()
        if fast_policy is not None or comfort_policy is not None:  # loads them once to check
            MergedController.from_package(fast=fast_policy, comfort=comfort_policy)
        place = where.scenario_fields(scenario, net, route, demand)
    except (FileNotFoundError, ValueError, CheckpointError) as exc:
        print_error(exc)
        raise typer.Exit(2) from exc
    hosts = served_hosts(host, allow_host)
    if host not in LOOPBACK_HOSTS:
        console.print(
            f"[yellow]warning:[/yellow] binding {host} exposes the ride controls to the network"
        )
    console.print(f"answering Host names: {', '.join(sorted(hosts))}", highlight=False)
    stack = RealStack(backend, fast_policy, comfort_policy, place, language=language_config)
    app = create_app(stack, step_period_s=step_period, hosts=hosts, net_file=where.net_of(place))
    console.print(f"passenger page: http://{host}:{port}/  (Ctrl+C to stop)")
    run_server(app, host, port)


def register(app: typer.Typer) -> None:
    """Add the command to the CLI."""
    app.command("serve")(serve)
