"""Figures (matplotlib, Agg backend, PNG): speed profiles and training curves."""

from __future__ import annotations

import csv
import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from explaindrive.evaluation.aggregate import command_spans, speed_band

log = logging.getLogger(__name__)

COMMAND_COLOURS: dict[str, str] = {"fast": "tab:blue", "comfort": "tab:green", "stop": "tab:red"}
BAND_ALPHA = 0.25
DPI = 120


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Any, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    _pyplot().close(fig)
    log.info("wrote %s", path)
    return path


def plot_speed_bands(
    groups: Mapping[str, Sequence[Sequence[float]]],
    path: Path,
    stop_intervals: Mapping[str, Sequence[tuple[float, float | None]]] | None = None,
    title: str = "",
) -> Path:
    """Mean ego speed over time with a +-1 std band, one panel per group.

    Args:
        groups: panel title -> speed traces (one per episode) [m/s, one value per 1 s step].
        path: PNG to write.
        stop_intervals: panel title -> stop-command intervals to shade [s].
        title: figure title.

    Raises:
        ValueError: if there are no groups or a group has no non-empty trace.
    """
    if not groups:
        raise ValueError("plot_speed_bands needs at least one group")
    plt = _pyplot()
    n = len(groups)
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(6.0 * cols, 3.6 * rows), squeeze=False,
                             sharey=True)  # fmt: skip
    for ax, (name, traces) in zip(axes.flat, groups.items(), strict=False):
        band = speed_band(traces)
        for start, end in (stop_intervals or {}).get(name, ()):
            ax.axvspan(start, end if end is not None else band.time_s[-1],
                       color=COMMAND_COLOURS["stop"], alpha=0.12, linewidth=0)  # fmt: skip
        low, high = band.mean_mps - band.std_mps, band.mean_mps + band.std_mps
        ax.fill_between(band.time_s, low, high, alpha=BAND_ALPHA, color="tab:blue", linewidth=0,
                        label="±1 std")  # fmt: skip
        ax.plot(band.time_s, band.mean_mps, color="tab:blue", linewidth=1.2, label="mean")
        ax.set_title(f"{name} ({len(traces)} episodes)")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("ego speed [m/s]")
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


def plot_command_profile(
    speeds_mps: Sequence[float], commands: Sequence[str], path: Path, title: str = ""
) -> Path:
    """One episode's speed profile over bands coloured by the active command.

    Raises:
        ValueError: if the traces are empty or of different lengths.
    """
    if not speeds_mps or len(speeds_mps) != len(commands):
        raise ValueError("speed and command traces must be non-empty and of equal length")
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8.0, 3.8))
    seen: set[str] = set()
    for cmd, start, end in command_spans(commands):
        ax.axvspan(start, end, color=COMMAND_COLOURS.get(cmd, "grey"), alpha=0.15, linewidth=0,
                   label=None if cmd in seen else cmd)  # fmt: skip
        seen.add(cmd)
    t = np.arange(1, len(speeds_mps) + 1, dtype=float)
    ax.plot(t, speeds_mps, color="black", linewidth=1.2, label="ego speed")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("ego speed [m/s]")
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    return _save(fig, path)


def read_returns(csv_path: Path) -> np.ndarray:
    """Episode returns of a training run's ``episodes.csv``.

    Raises:
        ValueError: if the file has no ``return`` column.
        FileNotFoundError: if it is missing.
    """
    with Path(csv_path).open(newline="") as f:
        reader = csv.DictReader(f)
        if not reader.fieldnames or "return" not in reader.fieldnames:
            raise ValueError(f"{csv_path} has no 'return' column")
        return np.array([float(row["return"]) for row in reader], dtype=np.float64)


def plot_training_curves(runs: Mapping[str, Path], path: Path, window: int = 50) -> Path:
    """Episode reward and its ``window``-episode moving average, one panel per training run.

    Args:
        runs: panel title -> ``episodes.csv`` of a training run.
        path: PNG to write.
        window: moving-average window [episodes] (the paper uses 50).

    Raises:
        ValueError: if ``runs`` is empty or a CSV has no ``return`` column.
    """
    from explaindrive.agent.run_log import moving_average

    if not runs:
        raise ValueError("plot_training_curves needs at least one run")
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(runs), figsize=(6.0 * len(runs), 3.8), squeeze=False)
    for ax, (name, csv_path) in zip(axes.flat, runs.items(), strict=True):
        returns = read_returns(csv_path)
        x = np.arange(1, len(returns) + 1)
        ax.plot(x, returns, color="tab:blue", alpha=0.3, linewidth=0.7, label="episode reward")
        if len(returns):
            ax.plot(x, moving_average(returns, window), color="tab:blue", linewidth=1.4,
                    label=f"{window}-episode mean")  # fmt: skip
        ax.set_title(f"{name}: training reward ({len(returns)} episodes)")
        ax.set_xlabel("episode")
        ax.set_ylabel("reward")
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    return _save(fig, path)
