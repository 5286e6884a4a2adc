"""``explaindrive train``: train a fast or comfort D3QN agent on the SUMO scenario."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from explaindrive.cli import _scenario_options as where
from explaindrive.cli._errors import print_error
from explaindrive.cli._grid_options import check_ray_target
from explaindrive.cli._paths import refuse_bad_outputs
from explaindrive.limits import MAX_EPISODES, MAX_WORKERS

if TYPE_CHECKING:
    from explaindrive.agent.config import TrainConfig
    from explaindrive.agent.trainer import TrainResult

console = Console()


def _saved_config(out: Path) -> dict[str, Any] | None:
    from explaindrive.agent.config import ConfigError

    path = out / "config.json"
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise ConfigError(f"cannot read the run's config {path}: {exc}") from exc
    if not isinstance(data, dict):
        raise ConfigError(f"{path} does not hold a config mapping")
    return data


def resolve_config(
    mode: str,
    preset: str | None,
    config_file: Path | None,
    overrides: list[str],
    out: Path,
    resume: bool,
    **options: Any,
) -> TrainConfig:
    """The run's config: base (saved run when resuming, else preset), file, ``--set``, flags.

    Raises:
        ConfigError: on an unknown mode, preset, key or an invalid value.
    """
    from explaindrive.agent.config import (
        DEFAULT_PRESET,
        TRAIN_MODES,
        ConfigError,
        TrainConfig,
        build_config,
        load_config_file,
        parse_override,
    )

    if mode not in TRAIN_MODES:
        raise ConfigError(
            f"unknown mode {mode!r}: choose one of {', '.join(TRAIN_MODES)} "
            "(stop is not a separate agent; both agents learn to obey it)"
        )
    changes: dict[str, Any] = dict(parse_override(item) for item in overrides)
    from explaindrive.sim.scenario.choice import RANDOM

    place = {k: v for k, v in options.items() if v is not None}
    if place.keys() & {"scenario", "net_file", "route"} and place.get("scenario") != RANDOM:
        # a scenario or network given on the command line replaces the preset's family
        changes.update(scenario=None, scenario_paper_share=0.0)
    changes.update(place)
    changes["mode"] = mode
    saved = _saved_config(out) if resume and preset is None else None
    if saved is not None:
        data = dict(saved)
        if config_file is not None:
            data.update(load_config_file(config_file))
        return TrainConfig.from_dict({**data, **changes})
    return build_config(preset or DEFAULT_PRESET, config_file, changes)


ModeOption = Annotated[str, typer.Option("--mode", "-m", help="Agent to train: fast or comfort.")]
EpisodesOption = Annotated[
    int | None,
    typer.Option("--episodes", "-n", min=1, max=MAX_EPISODES, help="Training episodes."),
]
EnvsOption = Annotated[
    int | None,
    typer.Option(
        "--envs", min=1, max=MAX_WORKERS, help="Parallel SUMO processes (default: CPU count)."
    ),
]
OutOption = Annotated[
    Path | None, typer.Option("--out", "-o", help="Run directory (default: runs/<mode>).")
]
ResumeOption = Annotated[
    bool, typer.Option("--resume", help="Continue from the run's last checkpoint.")
]
PresetOption = Annotated[
    str | None,
    typer.Option(
        "--preset", help="passenger, safe or paper (default: passenger; the run's own on --resume)."
    ),
]
SeedOption = Annotated[int | None, typer.Option("--seed", help="Base seed of the run.")]
ConfigFileOption = Annotated[
    Path | None, typer.Option("--config", help="YAML/JSON file of config values.")
]
SetOption = Annotated[
    list[str] | None,
    typer.Option("--set", help="Override any config field: --set lr=3e-4 (repeatable)."),
]
ProgressOption = Annotated[
    bool, typer.Option("--progress/--no-progress", help="Show a progress bar.")
]
WorkerRayOption = Annotated[
    bool, typer.Option("--ray", help="Run the env workers as actors on a local Ray.")
]
WorkerRayAddressOption = Annotated[
    str | None, typer.Option("--ray-address", help="Run the env workers on this Ray cluster.")
]
SeedsOption = Annotated[
    str | None,
    typer.Option(
        "--seeds",
        help="Train one run per seed side by side (e.g. 0,1,2), then evaluate each "
        "on the same grid (see docs/agent.md).",
    ),
]


def train_command(
    mode: ModeOption,
    episodes: EpisodesOption = None,
    envs: EnvsOption = None,
    out: OutOption = None,
    resume: ResumeOption = False,
    preset: PresetOption = None,
    seed: SeedOption = None,
    config_file: ConfigFileOption = None,
    overrides: SetOption = None,
    progress: ProgressOption = True,
    ray: WorkerRayOption = False,
    ray_address: WorkerRayAddressOption = None,
    seeds: SeedsOption = None,
    scenario: where.ScenarioOption = None,
    net: where.NetOption = None,
    route: where.RouteOption = None,
    demand: where.DemandOption = None,
) -> None:
    """Train a D3QN driving agent with the paper's command schedule."""
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.agent.config import ConfigError
    from explaindrive.agent.trainer import Trainer

    try:
        place = where.scenario_fields(scenario, net, route, demand, allow_random=True)
    except where.ScenarioChoiceError as exc:
        print_error(exc)
        raise typer.Exit(2) from None
    if seeds is not None:
        run_args = seed_run_args(mode, episodes, envs, resume, preset, config_file,
                                 overrides or [], ray, ray_address)  # fmt: skip
        run_args += where.scenario_args(scenario, net, route, demand)
        _train_seeds(mode, seeds, seed, out, run_args)
        return
    out = out or Path("runs") / mode
    refuse_bad_outputs(folders=((out, "--out"),))
    try:
        if (problem := check_ray_target(ray, ray_address)) is not None:
            raise ConfigError(problem)
        config = resolve_config(
            mode.strip().lower(), preset, config_file, overrides or [], out, resume,
            episodes=episodes, num_envs=envs, seed=seed, **place,
        )  # fmt: skip
        trainer = Trainer(config, out, resume=resume, show_progress=progress, use_ray=ray,
                          ray_address=ray_address)  # fmt: skip
    except (ConfigError, CheckpointError) as exc:
        print_error(exc)
        raise typer.Exit(2) from None
    console.print(
        f"training [bold]{config.mode}[/bold]: {config.episodes} episodes on {config.envs} "
        f"env(s) -> {out}"
    )
    _print_result(config.mode, trainer.run())


def _print_result(mode: str, result: TrainResult) -> None:
    """The finished run's figures and files, as a table."""
    table = Table(title=f"{mode} agent trained", show_header=False)
    for key, value in (
        ("episodes", result.episodes),
        ("env steps", result.env_steps),
        ("updates", result.updates),
        ("wall time", f"{result.wall_time_s:.1f} s"),
        ("steps/s", f"{result.steps_per_s:.1f}"),
        ("policy", result.policy_path),
        ("training curve", result.curve_path),
    ):
        table.add_row(key, str(value))
    console.print(table)


def seed_run_args(
    mode: str,
    episodes: int | None,
    envs: int | None,
    resume: bool,
    preset: str | None,
    config_file: Path | None,
    overrides: list[str],
    ray: bool,
    ray_address: str | None,
) -> list[str]:
    """The ``train`` options every run of ``--seeds`` gets (its seed and folder are added)."""
    args = ["--mode", mode]
    for flag, value in (("--episodes", episodes), ("--envs", envs), ("--preset", preset),
                        ("--config", config_file), ("--ray-address", ray_address)):  # fmt: skip
        if value is not None:
            args += [flag, str(value)]
    for item in overrides:
        args += ["--set", item]
    args += ["--resume"] if resume else []
    args += ["--ray"] if ray else []
    return args


def _train_seeds(
    mode: str, seeds_text: str, seed: int | None, out: Path | None, train_args: list[str]
) -> None:
    """``--seeds``: one run per seed, then the combined table
    (:mod:`explaindrive.evaluation.sweep`)."""
    from explaindrive.agent.config import ConfigError
    from explaindrive.evaluation.parsing import SpecError, parse_seeds
    from explaindrive.evaluation.sweep import (
        DEFAULT_EVAL_SEEDS,
        DEFAULT_EVAL_STOPS,
        evaluate_seeds,
        train_seeds,
    )
    from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS

    try:
        if seed is not None:
            raise ConfigError("give --seed or --seeds, not both")
        seeds = parse_seeds(seeds_text)
    except (ConfigError, SpecError) as exc:
        print_error(exc)
        raise typer.Exit(2) from None
    out = out or Path("runs") / f"{mode}-seeds"
    listed = ", ".join(map(str, seeds))
    which = f"seeds {listed} side by side" if len(seeds) > 1 else f"seed {listed}"
    console.print(f"training {mode} with {which} -> {out}")
    codes = train_seeds(train_args, seeds, out)
    for s, code in codes.items():
        status = "done" if code == 0 else f"failed (exit {code}, see {out}/seed-{s}.log)"
        console.print(f"seed {s}: {status}")
    results = evaluate_seeds(out, seeds, parse_seeds(DEFAULT_EVAL_SEEDS), TRAFFIC_LEVELS,
                             DEFAULT_EVAL_STOPS)  # fmt: skip
    console.print((out / "seeds.md").read_text(encoding="utf-8"), markup=False)
    if not results or any(code != 0 for code in codes.values()):
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    """Add ``train`` to the CLI."""
    app.command("train")(train_command)
