"""Options and helpers shared by ``explaindrive evaluate``, ``report`` and ``train``: one
place each."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console

from explaindrive.cli._errors import print_error
from explaindrive.limits import MAX_STEPS, MAX_WORKERS
from explaindrive.sim.scenario.limits import TRAFFIC_LEVELS

if TYPE_CHECKING:
    from rich.progress import Progress

    from explaindrive.evaluation.runner import Progress as EpisodeProgress

err_console = Console(stderr=True, soft_wrap=True)  # an error line never wraps

DEFAULT_TRAFFIC = ",".join(f"{x:g}" for x in TRAFFIC_LEVELS)

FastPolicyOption = Annotated[
    Path | None, typer.Option("--fast-policy", help="Fast policy file instead of the shipped.")
]
ComfortPolicyOption = Annotated[
    Path | None,
    typer.Option("--comfort-policy", help="Comfort policy file instead of the shipped."),
]
ShieldOption = Annotated[
    bool,
    typer.Option("--shield/--no-shield", help="Agents act through the safety shield."),
]
WorkersOption = Annotated[
    int | None,
    typer.Option("--workers", min=1, max=MAX_WORKERS, help="Processes (default: one per CPU)."),
]
RayOption = Annotated[bool, typer.Option("--ray", help="Run the episodes on a local Ray.")]
RayAddressOption = Annotated[
    str | None, typer.Option("--ray-address", help="Run the episodes on this Ray cluster.")
]
TrafficOption = Annotated[str, typer.Option("--traffic", help="Traffic levels, comma-separated.")]
JsonOption = Annotated[
    Path | None, typer.Option("--json", help="Write every episode and the aggregates here.")
]
MaxStepsOption = Annotated[
    int, typer.Option("--max-steps", min=1, max=MAX_STEPS, help="Step limit per episode [s].")
]


def obs_noise_sd(text: str | None) -> tuple[float, float]:
    """``--obs-noise SD_M,SD_MPS`` as the config field ``(sd_m, sd_mps)``; no noise for ``None``.

    Raises:
        ValueError: naming the expected form or the accepted range.
    """
    if text is None:
        return (0.0, 0.0)
    from explaindrive.env.noise import parse_noise

    noise = parse_noise(text)
    return (noise.sd_m, noise.sd_mps)


def check_ray_target(ray: bool, ray_address: str | None) -> str | None:
    """The error message when both ``--ray`` and ``--ray-address`` are given, when either
    is given without Ray installed, or when nothing answers at ``--ray-address`` (within
    :data:`~explaindrive.limits.RAY_CONNECT_TIMEOUT_S`); else ``None``."""
    if ray and ray_address:
        return "give --ray or --ray-address, not both"
    if ray or ray_address:
        from explaindrive.agent.ray_pool import RAY_MISSING, ray_installed, unreachable_ray_address

        if not ray_installed():
            return RAY_MISSING
        if ray_address:
            return unreachable_ray_address(ray_address)
    return None


def progress_bar() -> Progress:
    """The episode progress bar (on stderr, so stdout keeps only the tables)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
        TimeElapsedColumn(), console=err_console, transient=True,
    )  # fmt: skip


@contextlib.contextmanager
def episode_progress(description: str, total: int) -> Iterator[EpisodeProgress]:
    """A progress bar over ``total`` episodes; yields the callback that advances it.

    A policy that cannot load or an episode that fails inside the block ends the command
    with one line and exit status 1.
    """
    from explaindrive.agent.checkpoint import CheckpointError

    try:
        with progress_bar() as bar:
            task = bar.add_task(description, total=total)
            yield lambda done, _total: bar.update(task, completed=done)
    except (CheckpointError, RuntimeError) as exc:
        print_error(exc)
        raise typer.Exit(1) from None
