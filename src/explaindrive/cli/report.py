"""``explaindrive report``: regenerate ``docs/results.md`` and its figures from one command."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from explaindrive.cli import _grid_options as grid
from explaindrive.cli._errors import print_error, refuse
from explaindrive.cli._grid_options import err_console
from explaindrive.cli._paths import refuse_bad_outputs
from explaindrive.evaluation.spec import POLICY_NAMES
from explaindrive.limits import MAX_SEEDS

if TYPE_CHECKING:
    from explaindrive.evaluation.report_plan import ReportPlan


ALL_POLICIES = ",".join(POLICY_NAMES)
OutOption = Annotated[Path, typer.Option("--out", help="The results document to write.")]
FigureDirOption = Annotated[
    Path | None,
    typer.Option("--figures", help="Figure directory (default: figures/ next to --out)."),
]
EpisodesPerCellOption = Annotated[
    int,
    typer.Option(
        "--episodes-per-cell", min=1, max=MAX_SEEDS, help="Seeds per traffic level (paper: 5)."
    ),
]
PoliciesOption = Annotated[
    str, typer.Option("--policies", help="Subset of " + ",".join(POLICY_NAMES) + ".")
]
RunsOption = Annotated[
    Path | None,
    typer.Option(
        "--runs",
        help="Training runs (<dir>/fast, <dir>/comfort) for the curves "
        "(default: the shipped policies' training logs).",
    ),
]
SeedTableOption = Annotated[
    list[Path] | None,
    typer.Option("--seed-table", help="A seeds.md of train --seeds to include (repeatable)."),
]
ExternalOption = Annotated[
    list[Path] | None,
    typer.Option(
        "--external",
        help="An evaluation JSON of a driver evaluated elsewhere on the same seeds and levels "
        "(e.g. scripts/train_sb3_baseline.py evaluate --json), added to the tables "
        "(repeatable).",
    ),
]
GeneralisationOption = Annotated[
    bool,
    typer.Option(
        "--generalisation/--no-generalisation",
        help="Add the table on 20 held-out generated scenarios and two netgenerate networks.",
    ),
]


def report_command(
    out: OutOption = Path("docs/results.md"),
    figures: FigureDirOption = None,
    episodes_per_cell: EpisodesPerCellOption = 5,
    traffic: grid.TrafficOption = grid.DEFAULT_TRAFFIC,
    policies: PoliciesOption = ALL_POLICIES,
    fast_policy: grid.FastPolicyOption = None,
    comfort_policy: grid.ComfortPolicyOption = None,
    shield: grid.ShieldOption = True,
    runs_dir: RunsOption = None,
    json_file: grid.JsonOption = None,
    workers: grid.WorkersOption = None,
    ray: grid.RayOption = False,
    ray_address: grid.RayAddressOption = None,
    max_steps: grid.MaxStepsOption = 1000,
    seed_tables: SeedTableOption = None,
    external: ExternalOption = None,
    generalisation: GeneralisationOption = True,
) -> None:
    """Evaluate the policies and baselines and rewrite the results document and figures."""
    from explaindrive.evaluation.report import external_runs, run_report

    refuse_bad_outputs(
        files=((out, "--out"), (json_file, "--json")), folders=((figures, "--figures"),)
    )
    plan = _plan(policies, episodes_per_cell, traffic, fast_policy, comfort_policy, max_steps,
                 shield, ray, ray_address, seed_tables or [])  # fmt: skip
    training_logs = _training_logs(plan, runs_dir)
    try:
        stored = external_runs(plan, external or [])
    except ValueError as exc:
        print_error(exc)
        raise typer.Exit(2) from None
    n = sum(len(run.episodes) for run in plan.runs)
    err_console.print(f"report: {len(plan.runs)} runs, {n} episodes")
    with grid.episode_progress("episodes", n) as progress:
        result = run_report(
            plan, out, figures_dir=figures, training_runs=training_logs,
            json_file=json_file, workers=workers, use_ray=ray, ray_address=ray_address,
            command_line="explaindrive " + " ".join(shlex.quote(a) for a in sys.argv[1:]),
            progress=progress, seed_tables=seed_tables or [], external=stored,
        )  # fmt: skip
    markdown = result.markdown
    if generalisation:
        markdown += _generalisation(plan, max_steps, workers, ray, ray_address)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(markdown, encoding="utf-8")
    for path in (out, *result.figures):
        err_console.print(f"wrote {path}")


def _generalisation(
    plan: ReportPlan, max_steps: int, workers: int | None, ray: bool, ray_address: str | None
) -> str:
    """The generalisation section (:mod:`explaindrive.evaluation.generalisation`)."""
    from explaindrive.cache import cache_dir
    from explaindrive.evaluation import generalisation as gen

    plans = gen.plan_generalisation(plan.policies, gen.scenario_groups(cache_dir()),
                                    max_steps=max_steps)  # fmt: skip
    n = sum(len(p.episodes) for p in plans.values())
    err_console.print(f"generalisation: {n} episodes")
    with grid.episode_progress("generalisation", n) as progress:
        return gen.run_generalisation(plans, workers=workers, use_ray=ray,
                                      ray_address=ray_address, progress=progress)  # fmt: skip


def _plan(
    policies: str, episodes_per_cell: int, traffic: str, fast_policy: Path | None,
    comfort_policy: Path | None, max_steps: int, shield: bool, ray: bool,
    ray_address: str | None, seed_tables: list[Path],
) -> ReportPlan:  # fmt: skip
    """The report's runs; a bad option ends the command with one line and status 2."""
    from explaindrive.evaluation.parsing import SpecError, parse_levels
    from explaindrive.evaluation.report_plan import parse_policy_list, plan_report

    problem = grid.check_ray_target(ray, ray_address)
    missing = [p for p in seed_tables if not p.is_file()]
    if problem is None and missing:
        problem = f"seed table not found: {missing[0]}"
    try:
        if problem is not None:
            raise SpecError(problem)
        return plan_report(
            parse_policy_list(policies), tuple(range(episodes_per_cell)), parse_levels(traffic),
            fast_path=fast_policy, comfort_path=comfort_policy, max_steps=max_steps,
            shield=shield,
        )  # fmt: skip
    except SpecError as exc:
        print_error(exc)
        raise typer.Exit(2) from None


def _training_logs(plan: ReportPlan, runs_dir: Path | None) -> dict[str, Path]:
    """``episodes.csv`` of each agent: from ``runs_dir``, else the shipped training logs.

    A ``runs_dir`` that is not a folder, or lacks the log of an agent of the plan, ends the
    command at once with one line and status 2 (before any episode is run).
    """
    from explaindrive.agent.controller import shipped_training_log

    agents = [name for name in plan.policies if name in ("fast", "comfort")]
    if runs_dir is None:
        return {name: shipped_training_log(name) for name in agents}
    logs = {name: runs_dir / name / "episodes.csv" for name in agents}
    if not runs_dir.is_dir():
        refuse(f"--runs {runs_dir}: no such folder")
    if missing := [path for path in logs.values() if not path.is_file()]:
        refuse(f"--runs {runs_dir}: no training log {missing[0]}")
    return logs


def register(app: typer.Typer) -> None:
    """Add ``report`` to the CLI."""
    app.command("report")(report_command)
