"""Training seeds side by side: several runs of one policy on the same grid.

Each run (a training run directory or a policy file) is evaluated on the same seeds,
traffic levels and command schedule; :func:`seed_table` gives one row per run and then the
mean and the spread (population standard deviation) of every column, so that a result is
read as a property of the training recipe rather than of one lucky seed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from explaindrive.evaluation.aggregate import Aggregate, aggregate, mean, pstd
from explaindrive.evaluation.runner import EpisodeRecord, Progress, run_grid, shield_counts
from explaindrive.evaluation.spec import parse_policy, plan_run
from explaindrive.evaluation.tables import fmt, markdown_table


@dataclass(frozen=True)
class SeedResult:
    """One run's figures over the grid."""

    run: str
    overall: Aggregate
    steps: int
    shield_overrides: int

    @property
    def shield_share(self) -> float:
        """Share of the steps in which the shield replaced (or would have) the network."""
        return self.shield_overrides / self.steps if self.steps else 0.0


def seed_result(run: str, records: Sequence[EpisodeRecord]) -> SeedResult:
    """Summarise the records of one run."""
    overrides, steps = shield_counts(records)
    return SeedResult(run, aggregate([r.result for r in records]), steps, overrides)


def evaluate_runs(
    runs: Sequence[str],
    seeds: Sequence[int],
    levels: Sequence[float],
    *,
    stop_schedule: str | None = None,
    shield: bool = False,
    workers: int | None = None,
    progress: Progress | None = None,
) -> list[SeedResult]:
    """Evaluate every run on the same grid (bare networks unless ``shield``).

    Raises:
        SpecError: on a bad run path or schedule.
        CheckpointError: if a policy cannot be loaded.
    """
    results = []
    for run in runs:
        policy = parse_policy(run, shield=shield)
        plan = plan_run(policy, seeds, levels, stop_schedule=stop_schedule)
        records = run_grid(plan.episodes, workers=workers, progress=progress)
        results.append(seed_result(run, records))
    return results


_COLUMNS: tuple[tuple[str, str], ...] = (
    ("collisions", "collision_episodes"),
    ("red-light runs", "red_light_runs"),
    ("ped-yield viol.", "ped_violations"),
    ("yield viol.", "yield_violations"),
    ("speeding steps", "speeding_steps"),
    ("stops over bound", "stop_bound_misses"),
    ("mean speed m/s", "mean_speed_mps"),
    ("avg jerk m/s^3", "avg_jerk_mps3"),
    ("avg TH s", "avg_headway_s"),
)


def _cells(result: SeedResult) -> list[float | int | None]:
    values: list[float | int | None] = [getattr(result.overall, key) for _, key in _COLUMNS]
    return [*values, 100.0 * result.shield_share]


def seed_table(results: Sequence[SeedResult]) -> str:
    """Markdown: one row per run, then the mean and the spread of each column."""
    header = ["run", "episodes", *(name for name, _ in _COLUMNS), "shield share %"]
    rows = [[r.run, str(r.overall.episodes), *(fmt(v) for v in _cells(r))] for r in results]
    columns = list(zip(*(_cells(r) for r in results), strict=True))
    present = [[v for v in col if v is not None] for col in columns]
    rows.append(["mean", "", *(fmt(mean(map(float, c))) for c in present)])
    rows.append(["spread (std)", "", *(fmt(pstd(map(float, c))) for c in present)])
    return markdown_table(header, rows)
