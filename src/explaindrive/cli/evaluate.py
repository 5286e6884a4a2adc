"""``explaindrive evaluate``: run a policy over a seed x traffic-level grid and report it."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from explaindrive.cli._errors import error_line
from explaindrive.cli._grid_options import (
    ComfortPolicyOption,
    FastPolicyOption,
    MaxStepsOption,
    RayAddressOption,
    RayOption,
    ShieldOption,
    WorkersOption,
    check_ray_target,
)
from explaindrive.evaluation.paper import PAPER_SEEDS, PAPER_TRAFFIC_LEVELS

console = Console()
err_console = Console(stderr=True)

DEFAULT_SEEDS = f"{PAPER_SEEDS[0]}-{PAPER_SEEDS[-1]}"
DEFAULT_TRAFFIC = ",".join(f"{x:g}" for x in PAPER_TRAFFIC_LEVELS)


def progress_bar() -> Progress:
    """The episode progress bar (on stderr, so stdout keeps only the tables)."""
    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
        TimeElapsedColumn(), console=err_console, transient=True,
    )  # fmt: skip


def evaluate_command(
    policy: Annotated[
        str,
        typer.Argument(help="fast | comfort | merged | krauss | idm | a policy .pt / run dir."),
    ],
    seeds: Annotated[str, typer.Option("--seeds", help="Seeds: 0-4 or 0,3,7.")] = DEFAULT_SEEDS,
    traffic: Annotated[
        str, typer.Option("--traffic", help="Traffic levels, comma-separated.")
    ] = DEFAULT_TRAFFIC,
    stop_schedule: Annotated[
        str | None,
        typer.Option("--stop-schedule", help="Stop injections [s], e.g. 60-75,150-165."),
    ] = None,
    commands: Annotated[
        str | None,
        typer.Option(
            "--commands", help='Command segments [s], e.g. "fast:0-90,stop:90-110,comfort:110-".'
        ),
    ] = None,
    json_file: Annotated[
        Path | None, typer.Option("--json", help="Write every episode and the aggregates here.")
    ] = None,
    figures: Annotated[
        Path | None, typer.Option("--figures", help="Write PNG figures into this directory.")
    ] = None,
    workers: WorkersOption = None,
    ray: RayOption = False,
    ray_address: RayAddressOption = None,
    max_steps: MaxStepsOption = 1000,
    fast_policy: FastPolicyOption = None,
    comfort_policy: ComfortPolicyOption = None,
    shield: ShieldOption = True,
    episodes: Annotated[
        bool, typer.Option("--episodes/--no-episodes", help="Also print one row per episode.")
    ] = True,
) -> None:
    """Evaluate a policy or a SUMO baseline; prints Markdown tables in the paper's layout."""
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.evaluation import figures as figs
    from explaindrive.evaluation import tables
    from explaindrive.evaluation.aggregate import summarize
    from explaindrive.evaluation.runner import run_grid
    from explaindrive.evaluation.schema import run_document, write_json
    from explaindrive.evaluation.spec import (
        SpecError,
        parse_levels,
        parse_policy,
        parse_seeds,
        plan_run,
    )

    try:
        spec = parse_policy(
            policy, fast_path=fast_policy, comfort_path=comfort_policy, shield=shield
        )
        plan = plan_run(
            spec, parse_seeds(seeds), parse_levels(traffic),
            stop_schedule=stop_schedule, commands=commands, max_steps=max_steps,
        )  # fmt: skip
    except SpecError as exc:
        err_console.print(error_line(exc))
        raise typer.Exit(2) from None
    if (problem := check_ray_target(ray, ray_address)) is not None:
        err_console.print(error_line(problem))
        raise typer.Exit(2)

    n = len(plan.episodes)
    err_console.print(f"evaluating [bold]{plan.name}[/bold]: {n} episode(s)")
    try:
        with progress_bar() as bar:
            task = bar.add_task(plan.name, total=n)
            records = run_grid(
                plan.episodes, workers=workers, use_ray=ray, ray_address=ray_address,
                progress=lambda done, _total: bar.update(task, completed=done),
            )  # fmt: skip
    except (CheckpointError, RuntimeError) as exc:
        err_console.print(error_line(exc))
        raise typer.Exit(1) from None

    summary = summarize(plan.name, [(r.spec.traffic_level, r.result) for r in records])
    out = Console(highlight=False, markup=False, soft_wrap=True)
    out.print(f"## {plan.name}\n")
    out.print(tables.paper_table([summary]) + "\n")
    out.print(tables.level_table([summary]) + "\n")
    out.print(tables.safety_table([summary]) + "\n")
    if spec.kind != "baseline":
        steps = sum(r.result.steps for r in records)
        overrides = sum(r.shield_overrides for r in records)
        out.print(tables.shield_line(overrides, steps, spec.shield) + "\n")
    if episodes:
        out.print(tables.episode_table(
            [(r.spec.seed, r.spec.traffic_level, r.result) for r in records]
        ))  # fmt: skip
    if json_file is not None:
        write_json(json_file, [run_document(plan.name, records)])
        err_console.print(f"wrote {json_file}")
    if figures is not None:
        written = [
            figs.plot_speed_bands(
                {plan.name: [r.speeds_mps for r in records]}, figures / "speed_profile.png",
                stop_intervals={plan.name: plan.stop_intervals},
            ),
        ]  # fmt: skip
        if plan.episodes[0].schedule:
            first = records[0]
            written.append(figs.plot_command_profile(
                first.speeds_mps, first.commands, figures / "command_profile.png",
                title=f"{plan.name}: seed {first.spec.seed}, traffic {first.spec.traffic_level:g}",
            ))  # fmt: skip
        for policy_file in spec.paths[:1] if spec.kind == "agent" else ():
            log_csv = Path(policy_file).parent / "episodes.csv"
            if log_csv.is_file():
                written.append(
                    figs.plot_training_curves({spec.name: log_csv}, figures / "training_curve.png")
                )
        for path in written:
            err_console.print(f"wrote {path}")


def register(app: typer.Typer) -> None:
    """Add ``evaluate`` to the CLI."""
    app.command("evaluate")(evaluate_command)
