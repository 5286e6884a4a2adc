"""``ride.png``: speed over time with command bands and explanation markers."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from explaindrive.ride.records import StepRecord

COMMAND_COLOURS = {"fast": "#d62728", "comfort": "#2ca02c", "stop": "#7f7f7f"}


def command_bands(records: Sequence[StepRecord]) -> list[tuple[float, float, str]]:
    """Maximal time intervals ``(start_s, end_s, command)`` of constant command."""
    bands: list[tuple[float, float, str]] = []
    for rec in records:
        start = rec.t - 1.0
        if bands and bands[-1][2] == rec.command:
            bands[-1] = (bands[-1][0], rec.t, rec.command)
        else:
            bands.append((start, rec.t, rec.command))
    return bands


def plot_ride(records: Sequence[StepRecord], out_file: Path, title: str = "Ride") -> Path:
    """Draw the ride's speed profile like the paper's merged-model figure."""
    fig, ax = plt.subplots(figsize=(11, 4))
    for start, end, cmd in command_bands(records):
        ax.axvspan(start, end, color=COMMAND_COLOURS.get(cmd, "#cccccc"), alpha=0.12, lw=0)
    t = [r.t for r in records]
    ax.plot(t, [r.speed_mps for r in records], color="k", lw=1.6, label="ego speed")
    ax.step(
        t,
        [r.limit_mps for r in records],
        where="post",
        color="#1f77b4",
        lw=1,
        ls="--",
        label="speed limit",
    )
    ex = [r for r in records if r.explanation]
    if ex:
        ax.plot(
            [r.t for r in ex],
            [r.speed_mps for r in ex],
            "v",
            color="#ff7f0e",
            ms=8,
            label="explanation",
        )
    handles, labels = ax.get_legend_handles_labels()
    for cmd, colour in COMMAND_COLOURS.items():
        handles.append(plt.Rectangle((0, 0), 1, 1, color=colour, alpha=0.25))
        labels.append(f"{cmd} command")
    ax.legend(handles, labels, loc="upper right", fontsize=8, ncol=2)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("speed [m/s]")
    ax.set_ylim(bottom=0)
    ax.set_title(title)
    fig.tight_layout()
    out_file.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out_file, dpi=120)
    plt.close(fig)
    return out_file
