"""``explaindrive train``: train a fast or comfort D3QN agent on the SUMO scenario."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from explaindrive.agent.config import (
    TRAIN_MODES,
    ConfigError,
    TrainConfig,
    build_config,
    load_config_file,
    parse_override,
)
from explaindrive.cli._errors import error_line

console = Console()


def _saved_config(out: Path) -> dict[str, Any] | None:
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
    if mode not in TRAIN_MODES:
        raise ConfigError(
            f"unknown mode {mode!r}: choose one of {', '.join(TRAIN_MODES)} "
            "(stop is not a separate agent; both agents learn to obey it)"
        )
    changes: dict[str, Any] = dict(parse_override(item) for item in overrides)
    changes.update({k: v for k, v in options.items() if v is not None})
    changes["mode"] = mode
    saved = _saved_config(out) if resume and preset is None else None
    if saved is not None:
        data = dict(saved)
        if config_file is not None:
            data.update(load_config_file(config_file))
        return TrainConfig.from_dict({**data, **changes})
    return build_config(preset or "safe", config_file, changes)


def train_command(
    mode: Annotated[str, typer.Option("--mode", "-m", help="Agent to train: fast or comfort.")],
    episodes: Annotated[
        int | None, typer.Option("--episodes", "-n", help="Training episodes.")
    ] = None,
    envs: Annotated[
        int | None, typer.Option("--envs", help="Parallel SUMO processes (default: CPU count).")
    ] = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Run directory (default: runs/<mode>).")
    ] = None,
    resume: Annotated[
        bool, typer.Option("--resume", help="Continue from the run's last checkpoint.")
    ] = False,
    preset: Annotated[
        str | None,
        typer.Option("--preset", help="safe or paper (default: safe; the run's own on --resume)."),
    ] = None,
    seed: Annotated[int | None, typer.Option("--seed", help="Base seed of the run.")] = None,
    config_file: Annotated[
        Path | None, typer.Option("--config", help="YAML/JSON file of config values.")
    ] = None,
    overrides: Annotated[
        list[str] | None,
        typer.Option("--set", help="Override any config field: --set lr=3e-4 (repeatable)."),
    ] = None,
    progress: Annotated[
        bool, typer.Option("--progress/--no-progress", help="Show a progress bar.")
    ] = True,
) -> None:
    """Train a D3QN driving agent with the paper's command schedule."""
    from explaindrive.agent.checkpoint import CheckpointError
    from explaindrive.agent.trainer import Trainer

    out = out or Path("runs") / mode
    try:
        config = resolve_config(
            mode.strip().lower(), preset, config_file, overrides or [], out, resume,
            episodes=episodes, num_envs=envs, seed=seed,
        )  # fmt: skip
        trainer = Trainer(config, out, resume=resume, show_progress=progress)
    except (ConfigError, CheckpointError) as exc:
        console.print(error_line(exc))
        raise typer.Exit(2) from None
    console.print(
        f"training [bold]{config.mode}[/bold]: {config.episodes} episodes on {config.envs} "
        f"env(s) -> {out}"
    )
    result = trainer.run()
    table = Table(title=f"{config.mode} agent trained", show_header=False)
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


def register(app: typer.Typer) -> None:
    """Add ``train`` to the CLI."""
    app.command("train")(train_command)
