"""``explaindrive demo``: one episode with the rule-based driver, summarised."""

from __future__ import annotations

import typer
from rich.console import Console
from rich.table import Table

from explaindrive.cli._errors import print_error
from explaindrive.limits import MAX_SEED


def demo(
    seed: int = typer.Option(0, min=0, max=MAX_SEED, help="Episode seed."),
    traffic: float = typer.Option(1.0, help="Traffic level (1.0 = 900 veh/h)."),
    command: str = typer.Option("fast", help="Passenger command: fast, comfort or stop."),
) -> None:
    """Drive one episode with the cautious rule-based driver and print its figures."""
    from explaindrive.commands import Command
    from explaindrive.env.config import EnvConfig
    from explaindrive.env.metrics import EpisodeMetrics
    from explaindrive.env.scripted import CautiousDriver
    from explaindrive.env.urban_drive import UrbanDriveEnv

    console = Console()
    try:
        cmd = Command.parse(command)
        env = UrbanDriveEnv(EnvConfig(traffic_level=traffic))
    except (ValueError, FileNotFoundError) as exc:
        print_error(exc)
        raise typer.Exit(2) from exc
    driver = CautiousDriver()
    metrics = EpisodeMetrics()
    try:
        obs, _ = env.reset(seed=seed, options={"command": cmd.label})
        done = False
        while not done:
            obs, reward, terminated, truncated, info = env.step(driver(obs))
            metrics.update(info, reward)
            done = terminated or truncated
    finally:
        env.close()
    res = metrics.result()
    table = Table(title=f"Rule-based driver, seed {seed}, traffic {traffic:g}, command {cmd.label}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    rows = [
        ("SUMO steps", str(res.steps)),
        ("mean speed \\[m/s]", f"{res.mean_speed_mps:.3f}"),
        ("avg time headway \\[s]", _fmt(res.avg_headway_s)),
        ("avg TTC \\[s]", _fmt(res.avg_ttc_s)),
        ("avg |jerk| \\[m/s^3]", f"{res.avg_jerk_mps3:.3f}"),
        ("collisions", str(res.collisions)),
        ("red-light runs", str(res.red_light_runs)),
        ("pedestrian-yield violations", str(res.ped_violations)),
        ("yield violations", str(res.yield_violations)),
        ("speeding steps", str(res.speeding_steps)),
        ("distance \\[m]", f"{res.distance_m:.1f}"),
        ("travel time \\[s]", _fmt(res.travel_time_s)),
        ("episode reward", f"{res.total_reward:.1f}"),
    ]
    for row in rows:
        table.add_row(*row)
    console.print(table)


def _fmt(value: float | None) -> str:
    return "-" if value is None else f"{value:.3f}"


def register(app: typer.Typer) -> None:
    """Add the command to the CLI."""
    app.command("demo")(demo)
