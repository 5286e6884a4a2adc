"""``docs/results.md``: every table and figure of the paper for our policies and the baselines.

:func:`run_report` evaluates the runs of a plan (:mod:`~explaindrive.evaluation.report_plan`)
in one grid (so the pool or Ray cluster stays busy), writes the figures and returns the
Markdown of :mod:`~explaindrive.evaluation.report_sections`.
"""

from __future__ import annotations

import logging
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from explaindrive.evaluation import figures as figs
from explaindrive.evaluation.aggregate import summarize
from explaindrive.evaluation.paper import PAPER_MERGED_COMMANDS
from explaindrive.evaluation.report_plan import ReportPlan
from explaindrive.evaluation.report_sections import results_markdown, seeds_section, shield_section
from explaindrive.evaluation.runner import EpisodeRecord, Progress, run_grid
from explaindrive.evaluation.schema import StoredRun, read_runs, run_document, write_json
from explaindrive.evaluation.spec import AGENTS, BASELINES, MERGED

log = logging.getLogger(__name__)

SPEED_FIGURES: tuple[tuple[Collection[str], str, str], ...] = (
    (AGENTS, "speed_profiles.png", "Ego speed, mean ± 1 std over the episodes"),
    (BASELINES, "baseline_speed_profiles.png",
     "SUMO baselines: ego speed, mean ± 1 std over the episodes"),
)  # fmt: skip
"""The speed-band figures: (policies of the figure, file name, title)."""


@dataclass
class ReportResult:
    """What :func:`run_report` produced."""

    markdown: str
    figures: list[Path] = field(default_factory=list)
    records: dict[str, list[EpisodeRecord]] = field(default_factory=dict)


def run_report(
    plan: ReportPlan,
    out_md: Path,
    *,
    figures_dir: Path | None = None,
    training_runs: Mapping[str, Path] | None = None,
    json_file: Path | None = None,
    command_line: str = "explaindrive report",
    workers: int | None = None,
    use_ray: bool = False,
    ray_address: str | None = None,
    progress: Progress | None = None,
    seed_tables: Sequence[Path] = (),
    external: Mapping[str, tuple[StoredRun, str]] | None = None,
) -> ReportResult:
    """Evaluate every run of ``plan``, write the figures, and return the document's Markdown.

    Args:
        plan: from :func:`~explaindrive.evaluation.report_plan.plan_report`.
        out_md: where the document will be written (figure links are relative to it).
        figures_dir: figure directory (default: ``figures/`` next to ``out_md``).
        training_runs: agent name -> ``episodes.csv`` of its training run.
        json_file: also write every episode and aggregate here.
        command_line: the command shown as the way to regenerate the document.
        workers: local processes (or local Ray CPUs).
        use_ray: run on a local Ray.
        ray_address: run on this Ray cluster.
        progress: called after each finished episode.
        seed_tables: ``seeds.md`` files of ``train --seeds`` runs to include.
        external: runs of drivers evaluated elsewhere, from :func:`external_runs`; they join
            the tables.
    """
    stored = external or {}
    figures_dir = figures_dir or out_md.parent / "figures"
    specs = [ep for run in plan.runs for ep in run.episodes]
    records = run_grid(specs, workers=workers, use_ray=use_ray, ray_address=ray_address,
                       progress=progress)  # fmt: skip
    by_run: dict[str, list[EpisodeRecord]] = {}
    i = 0
    for run in plan.runs:
        by_run[run.name] = records[i : i + len(run.episodes)]
        i += len(run.episodes)
    summaries = {
        name: summarize(name, [(r.spec.traffic_level, r.result) for r in recs])
        for name, recs in by_run.items()
    }
    for name, (ext, _what) in stored.items():
        summaries[name] = summarize(name, [(lvl, res) for lvl, _s, res in ext.episodes])
    written = _figures(plan, by_run, figures_dir, training_runs or {})
    if json_file is not None:
        write_json(json_file, [run_document(name, recs) for name, recs in by_run.items()])
    described = {name: what for name, (_run, what) in stored.items()}
    md = results_markdown(plan, summaries, by_run, written, out_md, command_line, described)
    md += shield_section(plan, by_run) + seeds_section(seed_tables)
    return ReportResult(md, written, by_run)


def external_runs(plan: ReportPlan, files: Sequence[Path]) -> dict[str, tuple[StoredRun, str]]:
    """The runs of evaluation files (:func:`~explaindrive.evaluation.schema.write_json`) of
    drivers evaluated elsewhere, such as a Stable-Baselines3 model, by name, each with a line
    saying what it is.

    Raises:
        ValueError: for a file that cannot be read, a run off the report's grid (its seeds
            and traffic levels) or one named like another run.
    """
    taken = {run.name for run in plan.runs}
    grid = sorted((lvl, seed) for lvl in plan.levels for seed in plan.seeds)
    out: dict[str, tuple[StoredRun, str]] = {}
    for path in files:
        for run in read_runs(path):
            if run.name in taken or run.name in out:
                raise ValueError(f"{path}: run {run.name!r} has the name of another run")
            if sorted((lvl, seed) for lvl, seed, _r in run.episodes) != grid:
                raise ValueError(
                    f"{path}: run {run.name!r} is not on the report's grid (seeds "
                    f"{list(plan.seeds)} x levels {list(plan.levels)})"
                )
            what = f"evaluated outside the report, read from `{path}`"
            out[run.name] = (run, what)
    return out


def _speed_panels(
    plan: ReportPlan, by_run: Mapping[str, list[EpisodeRecord]], group: Collection[str]
) -> dict[str, list[tuple[float, ...]]]:
    """Speed traces per run, for each policy of ``group``: its plain run and its stop run."""
    return {
        title: [r.speeds_mps for r in by_run[title]]
        for name in plan.policies
        if name in group
        for title in (name, f"{name} + stops")
        if title in by_run
    }


def _figures(
    plan: ReportPlan,
    by_run: Mapping[str, list[EpisodeRecord]],
    figures_dir: Path,
    training_runs: Mapping[str, Path],
) -> list[Path]:
    stops = {run.name: run.stop_intervals for run in plan.runs}
    written: list[Path] = []
    for group, file_name, title in SPEED_FIGURES:
        panels = _speed_panels(plan, by_run, group)
        if panels:
            written.append(figs.plot_speed_bands(
                panels, figures_dir / file_name, stop_intervals=stops, title=title
            ))  # fmt: skip
    if MERGED in by_run:
        rec = by_run[MERGED][0]
        written.append(figs.plot_command_profile(
            rec.speeds_mps, rec.commands, figures_dir / "merged_profile.png",
            title=f"merged controller, {PAPER_MERGED_COMMANDS} "
                  f"(seed {rec.spec.seed}, traffic {rec.spec.traffic_level:g})",
        ))  # fmt: skip
    curves = {name: p for name, p in training_runs.items() if Path(p).is_file()}
    if curves:
        written.append(figs.plot_training_curves(curves, figures_dir / "training_curves.png"))
    return written
