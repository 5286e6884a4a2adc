"""``explaindrive evaluate``: run a policy over a seed x traffic-level grid and report it."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console

from explaindrive.cli import _grid_options as grid
from explaindrive.cli import _scenario_options as where
from explaindrive.cli._errors import print_error
from explaindrive.cli._grid_options import err_console
from explaindrive.cli._paths import refuse_bad_outputs
from explaindrive.evaluation.paper import PAPER_SEEDS

if TYPE_CHECKING:
    from explaindrive.evaluation.spec import PolicySpec, RunPlan

DEFAULT_SEEDS = f"{PAPER_SEEDS[0]}-{PAPER_SEEDS[-1]}"


PolicyArgument = Annotated[
    str, typer.Argument(help="fast | comfort | merged | krauss | idm | a policy .pt / run dir.")
]
SeedsOption = Annotated[str, typer.Option("--seeds", help="Seeds: 0-4 or 0,3,7.")]
StopScheduleOption = Annotated[
    str | None, typer.Option("--stop-schedule", help="Stop injections [s], e.g. 60-75,150-165.")
]
CommandsOption = Annotated[
    str | None,
    typer.Option(
        "--commands", help='Command segments [s], e.g. "fast:0-90,stop:90-110,comfort:110-".'
    ),
]
FiguresOption = Annotated[
    Path | None, typer.Option("--figures", help="Write PNG figures into this directory.")
]
ObsNoiseOption = Annotated[
    str | None,
    typer.Option(
        "--obs-noise",
        help="Sensor noise SD_M,SD_MPS on the distances and speeds the policy and its shield "
        "see (e.g. 2,0.6); violations are judged on the true state.",
    ),
]
EpisodesOption = Annotated[
    bool, typer.Option("--episodes/--no-episodes", help="Also print one row per episode.")
]
ScenariosOption = Annotated[
    str | None,
    typer.Option(
        "--scenarios",
        help="Generated scenarios held out from training, e.g. random:100-119: tables per "
        "scenario and overall.",
    ),
]


def evaluate_command(
    policy: PolicyArgument,
    seeds: SeedsOption = DEFAULT_SEEDS,
    traffic: grid.TrafficOption = grid.DEFAULT_TRAFFIC,
    stop_schedule: StopScheduleOption = None,
    commands: CommandsOption = None,
    json_file: grid.JsonOption = None,
    figures: FiguresOption = None,
    workers: grid.WorkersOption = None,
    ray: grid.RayOption = False,
    ray_address: grid.RayAddressOption = None,
    max_steps: grid.MaxStepsOption = 1000,
    fast_policy: grid.FastPolicyOption = None,
    comfort_policy: grid.ComfortPolicyOption = None,
    shield: grid.ShieldOption = True,
    episodes: EpisodesOption = True,
    obs_noise: ObsNoiseOption = None,
    scenario: where.ScenarioOption = None,
    scenarios: ScenariosOption = None,
    net: where.NetOption = None,
    route: where.RouteOption = None,
    demand: where.DemandOption = None,
) -> None:
    """Evaluate a policy or a SUMO baseline; prints Markdown tables in the paper's layout."""
    from explaindrive.evaluation.parsing import parse_levels, parse_seeds
    from explaindrive.evaluation.schema import run_document, write_json
    from explaindrive.evaluation.spec import parse_policy, plan_run

    refuse_bad_outputs(files=((json_file, "--json"),), folders=((figures, "--figures"),))
    try:
        spec = parse_policy(
            policy, fast_path=fast_policy, comfort_path=comfort_policy, shield=shield
        )
        plan = plan_run(
            spec, parse_seeds(seeds), parse_levels(traffic),
            stop_schedule=stop_schedule, commands=commands, max_steps=max_steps,
            obs_noise=grid.obs_noise_sd(obs_noise),
        )  # fmt: skip
        plan = _in_scenarios(plan, scenario, scenarios, net, route, demand)
    except (ValueError, where.ScenarioChoiceError) as exc:
        print_error(exc)
        raise typer.Exit(2) from None
    if (problem := grid.check_ray_target(ray, ray_address)) is not None:
        print_error(problem)
        raise typer.Exit(2)
    _check_policies(spec)
    records = _run(plan, workers, ray, ray_address)
    _print_scenario_tables(plan.name, spec, records, episodes)
    if json_file is not None:
        write_json(json_file, [run_document(plan.name, records)])
        err_console.print(f"wrote {json_file}")
    if figures is not None:
        for path in _write_figures(plan, spec, records, figures):
            err_console.print(f"wrote {path}")


def _in_scenarios(
    plan: RunPlan,
    scenario: str | None,
    scenarios: str | None,
    net: Path | None,
    route: str | None,
    demand: Path | None,
) -> RunPlan:
    """The plan in the chosen scenario(s); generated ones are built here, once.

    Raises:
        SpecError, ScenarioChoiceError: naming the problem.
    """
    from explaindrive.cache import cache_dir
    from explaindrive.evaluation.scenarios import (
        ScenarioCase,
        network_case,
        over_scenarios,
        parse_scenarios,
    )
    from explaindrive.sim.network import parse_route

    fields = where.scenario_fields(scenario, net, route, demand)
    if scenarios is not None:
        if fields:
            raise where.ScenarioChoiceError("give --scenarios or one scenario, not both")
        return over_scenarios(plan, parse_scenarios(scenarios, cache_dir()))
    if not fields:
        return plan
    if scenario is not None:
        case = ScenarioCase(Path(scenario).name, tuple(fields.items()))
    else:
        assert net is not None and route is not None
        case = network_case(f"{net.name}:{'->'.join(parse_route(route))}", fields)
    return over_scenarios(plan, [case])


def _print_scenario_tables(name: str, spec: PolicySpec, records: list[Any], episodes: bool) -> None:
    """The tables per scenario, then over all of them (one scenario: its tables only)."""
    from explaindrive.evaluation.scenarios import by_scenario

    groups = by_scenario(records)
    if len(groups) > 1:
        for scenario_name, recs in groups.items():
            _print_tables(f"{name} on {scenario_name}", spec, recs, episodes)
        name = f"{name} overall ({len(groups)} scenarios)"
    elif records and records[0].spec.scenario_name != "paper":
        name = f"{name} on {records[0].spec.scenario_name}"
    _print_tables(name, spec, records, episodes and len(groups) == 1)


def _check_policies(spec: PolicySpec) -> None:
    """Load the policy files once before the run: one that is not a policy ends the command
    with one line and status 2, before any episode."""
    from explaindrive.agent.checkpoint import CheckpointError, load_policy

    try:
        for path in spec.paths:
            load_policy(Path(path))
    except CheckpointError as exc:
        print_error(exc)
        raise typer.Exit(2) from None


def _run(plan: RunPlan, workers: int | None, ray: bool, ray_address: str | None) -> list[Any]:
    """Run the grid with a progress bar; a policy that cannot load or an episode that fails
    ends the command with one line."""
    from explaindrive.evaluation.runner import run_grid

    n = len(plan.episodes)
    err_console.print(f"evaluating [bold]{plan.name}[/bold]: {n} episode(s)")
    with grid.episode_progress(plan.name, n) as progress:
        return run_grid(
            plan.episodes, workers=workers, use_ray=ray, ray_address=ray_address, progress=progress
        )


def _print_tables(name: str, spec: PolicySpec, records: list[Any], episodes: bool) -> None:
    """The paper's table, per level, safety, the shield's share and (optionally) episodes."""
    from explaindrive.evaluation import tables
    from explaindrive.evaluation.aggregate import summarize
    from explaindrive.evaluation.runner import shield_counts

    summary = summarize(name, [(r.spec.traffic_level, r.result) for r in records])
    out = Console(highlight=False, markup=False, soft_wrap=True)
    out.print(f"## {name}\n")
    out.print(tables.paper_table([summary]) + "\n")
    out.print(tables.level_table([summary]) + "\n")
    out.print(tables.safety_table([summary]) + "\n")
    out.print(tables.site_table([summary]) + "\n")
    out.print(tables.ride_table([summary]) + "\n")
    if spec.kind != "baseline":
        overrides, steps = shield_counts(records)
        out.print(tables.shield_line(overrides, steps, spec.shield) + "\n")
    if episodes:
        out.print(tables.episode_table(
            [(r.spec.seed, r.spec.traffic_level, r.result) for r in records]
        ))  # fmt: skip


def _write_figures(
    plan: RunPlan, spec: PolicySpec, records: list[Any], figures: Path
) -> list[Path]:
    """Speed bands, the first episode's command profile, and the training curve of a policy
    that sits in a training run directory."""
    from explaindrive.evaluation import figures as figs

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
    return written


def register(app: typer.Typer) -> None:
    """Add ``evaluate`` to the CLI."""
    app.command("evaluate")(evaluate_command)
