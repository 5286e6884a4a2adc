"""``explaindrive report``: regenerate ``docs/results.md`` and its figures from one command."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

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
from explaindrive.cli.evaluate import DEFAULT_TRAFFIC, err_console, progress_bar
from explaindrive.evaluation.spec import POLICY_NAMES


def report_command(
    out: Annotated[Path, typer.Option("--out", help="The results document to write.")] = Path(
        "docs/results.md"
    ),
    figures: Annotated[
        Path | None,
        typer.Option("--figures", help="Figure directory (default: figures/ next to --out)."),
    ] = None,
    episodes_per_cell: Annotated[
        int,
        typer.Option("--episodes-per-cell", min=1, help="Seeds per traffic level (paper: 5)."),
    ] = 5,
    traffic: Annotated[
        str, typer.Option("--traffic", help="Traffic levels, comma-separated.")
    ] = DEFAULT_TRAFFIC,
    policies: Annotated[
        str, typer.Option("--policies", help="Subset of " + ",".join(POLICY_NAMES) + ".")
    ] = ",".join(POLICY_NAMES),
    fast_policy: FastPolicyOption = None,
    comfort_policy: ComfortPolicyOption = None,
    shield: ShieldOption = True,
    runs_dir: Annotated[
        Path | None,
        typer.Option(
            "--runs",
            help="Training runs (<dir>/fast, <dir>/comfort) for the curves "
            "(default: the shipped policies' training logs).",
        ),
    ] = None,
    json_file: Annotated[
        Path | None, typer.Option("--json", help="Also write every episode and aggregate here.")
    ] = None,
    workers: WorkersOption = None,
    ray: RayOption = False,
    ray_address: RayAddressOption = None,
    max_steps: MaxStepsOption = 1000,
    seed_tables: Annotated[
        list[Path] | None,
        typer.Option("--seed-table", help="A seeds.md of train --seeds to include (repeatable)."),
    ] = None,
) -> None:
    """Evaluate the policies and baselines and rewrite the results document and figures."""
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.agent.controller import shipped_training_log
    from explaindrive.evaluation.report import parse_policy_list, plan_report, run_report
    from explaindrive.evaluation.spec import SpecError, parse_levels

    if (problem := check_ray_target(ray, ray_address)) is not None:
        err_console.print(error_line(problem))
        raise typer.Exit(2)
    missing = [p for p in seed_tables or [] if not p.is_file()]
    if missing:
        err_console.print(error_line(f"seed table not found: {missing[0]}"))
        raise typer.Exit(2)
    try:
        names = parse_policy_list(policies)
        plan = plan_report(
            names, tuple(range(episodes_per_cell)), parse_levels(traffic),
            fast_path=fast_policy, comfort_path=comfort_policy, max_steps=max_steps,
            shield=shield,
        )  # fmt: skip
    except SpecError as exc:
        err_console.print(error_line(exc))
        raise typer.Exit(2) from None
    n = sum(len(run.episodes) for run in plan.runs)
    err_console.print(f"report: {len(plan.runs)} runs, {n} episodes")
    command_line = "explaindrive " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    training = {
        name: (runs_dir / name / "episodes.csv" if runs_dir else shipped_training_log(name))
        for name in names
        if name in ("fast", "comfort")
    }
    try:
        with progress_bar() as bar:
            task = bar.add_task("episodes", total=n)
            result = run_report(
                plan, out, figures_dir=figures, training_runs=training, json_file=json_file,
                command_line=command_line, workers=workers, use_ray=ray, ray_address=ray_address,
                progress=lambda done, _total: bar.update(task, completed=done),
                seed_tables=seed_tables or [],
            )  # fmt: skip
    except (CheckpointError, RuntimeError) as exc:
        err_console.print(error_line(exc))
        raise typer.Exit(1) from None
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(result.markdown, encoding="utf-8")
    for path in (out, *result.figures):
        err_console.print(f"wrote {path}")


def register(app: typer.Typer) -> None:
    """Add ``report`` to the CLI."""
    app.command("report")(report_command)
