"""What a training run writes as it goes: ``episodes.csv``, TensorBoard scalars, a progress
bar and ``train.log`` (:class:`RunLog`, :func:`note`), and the training-curve figure at the
end."""

from __future__ import annotations

import csv
import importlib.util
import logging
import subprocess
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from explaindrive.agent.config import TrainConfig
from explaindrive.agent.rollout import EpisodeSummary
from explaindrive.extras import install_line

if TYPE_CHECKING:
    from explaindrive.agent.learner import UpdateStats

log = logging.getLogger(__name__)

CSV_FIELDS: tuple[str, ...] = (
    "episode", "env", "seed", "traffic_level", "stops", "return", "length", "env_steps",
    "epsilon", "collision", "red_light_run", "ped_violation", "yield_violation", "speeding_steps",
    "shield_share", "shielded", "mean_speed_mps", "distance_m", "terminated", "truncated",
    "wall_time_s",
)  # fmt: skip


def csv_row(
    ep: EpisodeSummary, worker: int, env_steps: int, epsilon: float, wall_time_s: float
) -> dict[str, Any]:
    """The ``episodes.csv`` row of a finished episode."""
    return {
        "episode": ep.index, "env": worker, "seed": ep.seed, "traffic_level": ep.traffic_level,
        "stops": int(ep.stops), "return": round(ep.ret, 4), "length": ep.length,
        "env_steps": env_steps, "epsilon": round(epsilon, 5),
        **{k: int(v) for k, v in ep.flags.items()}, "speeding_steps": ep.speeding_steps,
        "shield_share": round(ep.shield_share, 5), "shielded": int(ep.shielded),
        "mean_speed_mps": round(ep.mean_speed_mps, 4), "distance_m": round(ep.distance_m, 2),
        "terminated": int(ep.terminated), "truncated": int(not ep.terminated),
        "wall_time_s": round(wall_time_s, 2),
    }  # fmt: skip


class NoScalars:
    """Takes the place of TensorBoard's writer when the ``tensorboard`` extra is missing."""

    def add_scalar(self, tag: str, value: float, step: int) -> None:
        """Keep nothing."""

    def close(self) -> None:
        """Nothing to close."""


def scalar_writer(log_dir: Path, purge_step: int | None) -> Any:
    """TensorBoard's writer on ``log_dir``; without the ``tensorboard`` package (extra
    ``[tensorboard]``), :class:`NoScalars` after one warning naming the extra."""
    if importlib.util.find_spec("tensorboard") is None:
        log.warning("no TensorBoard scalars in %s: %s", log_dir, install_line("tensorboard"))
        return NoScalars()
    from torch.utils.tensorboard import SummaryWriter

    return SummaryWriter(str(log_dir), purge_step=purge_step)


def tb_episode(tb: Any, ep: EpisodeSummary, step: int, epsilon: float, sps: float) -> None:
    """The episode's TensorBoard scalars at env step ``step``."""
    tb.add_scalar("charts/episodic_return", ep.ret, step)
    tb.add_scalar("charts/episodic_length", ep.length, step)
    tb.add_scalar("charts/epsilon", epsilon, step)
    tb.add_scalar("charts/steps_per_second", sps, step)
    tb.add_scalar("charts/mean_speed_mps", ep.mean_speed_mps, step)
    for key, value in ep.flags.items():
        tb.add_scalar(f"safety/{key}", float(value), step)
    tb.add_scalar("safety/speeding_steps", ep.speeding_steps, step)
    tb.add_scalar("safety/shield_share", ep.shield_share, step)


def upgrade_csv(path: Path) -> None:
    """Rewrite an ``episodes.csv`` written with fewer columns than :data:`CSV_FIELDS` (a
    run resumed across a version that logs more) under the current header; a column it
    lacks is left empty in its rows.

    Raises:
        ValueError: if the file has a column :data:`CSV_FIELDS` does not know.
    """
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        header = list(reader.fieldnames or [])
        rows = list(reader)
    if header == list(CSV_FIELDS):
        return
    unknown = [name for name in header if name not in CSV_FIELDS]
    if unknown:
        raise ValueError(f"{path}: unknown column {unknown[0]!r}; not a training log")
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_FIELDS, restval="")
        writer.writeheader()
        writer.writerows(rows)


def truncate_csv(path: Path, rows: int) -> bool:
    """Keep the header and the first ``rows`` episodes; False if the file is missing."""
    if not path.exists():
        return False
    with path.open(newline="") as f:
        lines = list(csv.reader(f))
    with path.open("w", newline="") as f:
        csv.writer(f).writerows(lines[: rows + 1])
    return True


def moving_average(values: np.ndarray, window: int) -> np.ndarray:
    """Trailing moving average; the first ``window - 1`` points average what exists so far."""
    values = np.asarray(values, dtype=np.float64)
    if window <= 0:
        raise ValueError(f"window must be > 0, got {window}")
    csum = np.cumsum(np.insert(values, 0, 0.0))
    idx = np.arange(1, len(values) + 1)
    lo = np.maximum(idx - window, 0)
    return (csum[idx] - csum[lo]) / (idx - lo)


def plot_training_curve(csv_path: Path, png_path: Path, window: int = 50, title: str = "") -> Path:
    """The paper's training-curve figure: episode reward and its ``window``-episode average."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with csv_path.open(newline="") as f:
        returns = np.array([float(row["return"]) for row in csv.DictReader(f)])
    fig, ax = plt.subplots(figsize=(7, 4))
    x = np.arange(1, len(returns) + 1)
    ax.plot(x, returns, color="tab:blue", alpha=0.3, linewidth=0.8, label="episode reward")
    if len(returns):
        ax.plot(
            x, moving_average(returns, window), color="tab:blue", label=f"{window}-episode mean"
        )
    ax.set_xlabel("episode")
    ax.set_ylabel("total reward")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png_path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return png_path


def git_commit() -> str | None:
    """Commit of the source tree, if it is a git checkout."""
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"],
            cwd=Path(__file__).resolve().parent,
            capture_output=True,
            text=True,
            timeout=5,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


class Progress:
    """Rich progress bar (or nothing) showing episode, reward, epsilon and steps/s."""

    def __init__(self, enabled: bool, total: int, done: int, title: str) -> None:
        self._progress = None
        if not enabled:
            return
        from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeElapsedColumn
        from rich.progress import Progress as RichProgress

        self._progress = RichProgress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("reward {task.fields[reward]:>8.1f} (avg {task.fields[avg]:>8.1f})"),
            TextColumn("eps {task.fields[eps]:.3f}"),
            TextColumn("{task.fields[sps]:>6.0f} steps/s"),
            TimeElapsedColumn(),
        )
        self._task = self._progress.add_task(
            title, total=total, completed=done, reward=0.0, avg=0.0, eps=1.0, sps=0.0
        )
        self._progress.start()

    def update(self, done: int, reward: float, avg: float, eps: float, sps: float) -> None:
        """Show the latest figures."""
        if self._progress is not None:
            self._progress.update(
                self._task, completed=done, reward=reward, avg=avg, eps=eps, sps=sps
            )

    def close(self) -> None:
        """Remove the bar."""
        if self._progress is not None:
            self._progress.stop()


def note(out_dir: Path, level: int, message: str, *args: object) -> None:
    """Log ``message % args`` and append it, stamped, to ``out_dir/train.log``."""
    log.log(level, message, *args)
    out_dir.mkdir(parents=True, exist_ok=True)
    stamp = datetime.now(UTC).isoformat(timespec="seconds")
    with (out_dir / "train.log").open("a", encoding="utf-8") as f:
        f.write(f"{stamp} {logging.getLevelName(level)} {message % args}\n")


class RunLog:
    """The outputs a run writes as it goes: ``episodes.csv``, TensorBoard and the bar.

    Args:
        out_dir: the run directory.
        config: the run's config.
        append: continue ``episodes.csv`` (a resumed run) instead of writing it afresh.
        env_steps: the steps played so far (TensorBoard drops any scalars logged after them).
        episodes_done: the episodes finished so far (where the bar starts).
        show_progress: draw the rich progress bar.
    """

    def __init__(
        self, out_dir: Path, config: TrainConfig, *, append: bool, env_steps: int,
        episodes_done: int, show_progress: bool,
    ) -> None:  # fmt: skip
        self.config = config
        csv_path = out_dir / "episodes.csv"
        append = append and csv_path.exists()
        if append:
            upgrade_csv(csv_path)
        self._csv_file = csv_path.open("a" if append else "w", newline="")
        self._csv = csv.DictWriter(self._csv_file, fieldnames=CSV_FIELDS)
        if not append:
            self._csv.writeheader()
        self.tb = scalar_writer(out_dir / "tb", purge_step=env_steps or None)
        title = f"train {config.mode}"
        self._progress = Progress(show_progress, config.episodes, episodes_done, title)

    def episode(
        self, ep: EpisodeSummary, worker: int, *, env_steps: int, epsilon: float,
        wall_time_s: float, steps_per_s: float, episodes_done: int, mean_return: float,
    ) -> None:  # fmt: skip
        """A finished episode: its CSV row, its TensorBoard scalars and the bar."""
        self._csv.writerow(csv_row(ep, worker, env_steps, epsilon, wall_time_s))
        tb_episode(self.tb, ep, env_steps, epsilon, steps_per_s)
        self._progress.update(episodes_done, ep.ret, mean_return, epsilon, steps_per_s)

    def losses(self, stats: UpdateStats, step: int) -> None:
        """The TensorBoard scalars of a learner update at env step ``step``."""
        c = self.config
        self.tb.add_scalar("losses/td_loss", stats.td_loss, step)
        self.tb.add_scalar("losses/q_values", stats.q_values, step)
        self.tb.add_scalar("charts/learning_rate", stats.learning_rate, step)
        if c.safe_learning:
            self.tb.add_scalar("losses/unsafe_loss", stats.unsafe_loss, step)
            if c.boundary_weight > 0.0:
                self.tb.add_scalar("losses/boundary_loss", stats.boundary_loss, step)
        if c.grad_clip_norm is not None:
            self.tb.add_scalar("losses/grad_norm", stats.grad_norm, step)

    def flush(self) -> None:
        """Write the CSV rows so far to disk."""
        self._csv_file.flush()

    def close(self) -> None:
        """Remove the bar and close the files."""
        self._progress.close()
        self.tb.close()
        self._csv_file.close()
