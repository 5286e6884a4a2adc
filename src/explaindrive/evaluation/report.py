"""``docs/results.md``: every table and figure of the paper for our policies and the baselines.

:func:`plan_report` lays out the runs, :func:`run_report` evaluates them in one grid (so the
pool or Ray cluster stays busy), writes the figures and returns the Markdown; the discussion
is computed from the numbers by :func:`discussion`.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from explaindrive.env.metrics import TTC_INTERACTION_S
from explaindrive.evaluation import figures as figs
from explaindrive.evaluation import tables
from explaindrive.evaluation.aggregate import RunSummary, relative_difference, summarize
from explaindrive.evaluation.paper import (
    PAPER_MERGED_COMMANDS,
    PAPER_RESULTS,
    PAPER_STOP_SCHEDULE,
    PaperRow,
)
from explaindrive.evaluation.parsing import SpecError
from explaindrive.evaluation.runner import EpisodeRecord, Progress, run_grid, shield_counts
from explaindrive.evaluation.schema import run_document, write_json
from explaindrive.evaluation.spec import (
    AGENTS,
    BASELINES,
    MERGED,
    POLICY_NAMES,
    PolicySpec,
    RunPlan,
    parse_policy,
    plan_run,
)

log = logging.getLogger(__name__)

CLOSE_REL = 0.10  # relative difference under which a figure is called close to the paper's
SPEED_FIGURES: tuple[tuple[Collection[str], str, str], ...] = (
    (AGENTS, "speed_profiles.png", "Ego speed, mean ± 1 std over the episodes"),
    (BASELINES, "baseline_speed_profiles.png",
     "SUMO baselines: ego speed, mean ± 1 std over the episodes"),
)  # fmt: skip
"""The speed-band figures: (policies of the figure, file name, title)."""


@dataclass(frozen=True, slots=True)
class ReportPlan:
    """The runs of the results document.

    Attributes:
        runs: every run, in document order.
        policies: the resolved policies by name.
        seeds: seeds of every grid run.
        levels: traffic levels of every grid run.
    """

    runs: tuple[RunPlan, ...]
    policies: dict[str, PolicySpec]
    seeds: tuple[int, ...]
    levels: tuple[float, ...]


def parse_policy_list(text: str) -> tuple[str, ...]:
    """Parse ``fast,comfort,merged,krauss,idm`` (any subset, no duplicates).

    Raises:
        SpecError: on an unknown or repeated name.
    """
    names = [n.strip().lower() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in POLICY_NAMES]
    if not names or unknown:
        raise SpecError(f"policies must be among {', '.join(POLICY_NAMES)}; got {text!r}")
    if len(set(names)) != len(names):
        raise SpecError(f"policy list {text!r} repeats a name")
    return tuple(names)


def plan_report(
    policies: Sequence[str],
    seeds: Sequence[int],
    levels: Sequence[float],
    *,
    merged_seed: int = 0,
    merged_level: float = 1.0,
    fast_path: str | Path | None = None,
    comfort_path: str | Path | None = None,
    max_steps: int = 1000,
    shield: bool = True,
) -> ReportPlan:
    """Lay out the runs: each agent and baseline alone and with the paper's stop injections,
    and the merged fast -> stop -> comfort single episode.

    Raises:
        SpecError: on a missing policy file or an invalid grid.
    """
    resolved: dict[str, PolicySpec] = {}
    runs: list[RunPlan] = []
    for name in policies:
        spec = parse_policy(name, fast_path=fast_path, comfort_path=comfort_path, shield=shield)
        resolved[name] = spec
        if name == MERGED:
            runs.append(
                plan_run(
                    spec,
                    (merged_seed,),
                    (merged_level,),
                    commands=PAPER_MERGED_COMMANDS,
                    max_steps=max_steps,
                )
            )
            continue
        runs.append(plan_run(spec, seeds, levels, max_steps=max_steps))
        runs.append(
            plan_run(spec, seeds, levels, stop_schedule=PAPER_STOP_SCHEDULE, max_steps=max_steps)
        )
    return ReportPlan(tuple(runs), resolved, tuple(seeds), tuple(levels))


@dataclass
class ReportResult:
    """What :func:`run_report` produced."""

    markdown: str
    figures: list[Path] = field(default_factory=list)
    records: dict[str, list[EpisodeRecord]] = field(default_factory=dict)


def _card(spec: PolicySpec) -> dict[str, Any]:
    if not spec.paths:
        return {}
    try:
        data = json.loads(Path(spec.paths[0]).with_suffix(".json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


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
) -> ReportResult:
    """Evaluate every run of ``plan``, write the figures, and return the document's Markdown.

    Args:
        plan: from :func:`plan_report`.
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
    """
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
    written = _figures(plan, by_run, figures_dir, training_runs or {})
    if json_file is not None:
        write_json(json_file, [run_document(name, recs) for name, recs in by_run.items()])
    md = _markdown(plan, summaries, by_run, written, out_md, command_line)
    md += shield_section(plan, by_run) + seeds_section(seed_tables)
    return ReportResult(md, written, by_run)


def shield_section(plan: ReportPlan, by_run: Mapping[str, list[EpisodeRecord]]) -> str:
    """How often the safety shield replaced each agent's action, run by run."""
    lines = ["", "## Safety shield", ""]
    for name, records in by_run.items():
        base = name.split(" ")[0]
        if base not in plan.policies or plan.policies[base].kind == "baseline":
            continue
        overrides, steps = shield_counts(records)
        shielded = plan.policies[base].shield
        lines.append(f"- {name}: " + tables.shield_line(overrides, steps, shielded))
    return "\n".join(lines) + "\n" if len(lines) > 3 else ""


def seeds_section(paths: Sequence[Path]) -> str:
    """The ``seeds.md`` tables of training-seed runs, each under its run folder's name."""
    if not paths:
        return ""
    lines = ["", "## Training seeds", ""]
    for path in paths:
        body = path.read_text(encoding="utf-8").strip().splitlines()
        title = ""
        if body and body[0].startswith("#"):
            title, body = body[0].lstrip("# ").removeprefix("Training seeds: "), body[1:]
        while body and not body[0].strip():
            body = body[1:]
        lines += [f"### {path.parent.name}: {title}", "", *body, ""]
    return "\n".join(lines)


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


def _rel(path: Path, base: Path) -> str:
    try:
        return str(path.resolve().relative_to(base.resolve().parent))
    except ValueError:
        return str(path)


def _markdown(
    plan: ReportPlan,
    summaries: Mapping[str, RunSummary],
    by_run: Mapping[str, list[EpisodeRecord]],
    written: Sequence[Path],
    out_md: Path,
    command_line: str,
) -> str:
    """The document: how it was made, the policies, the tables, the figures, the discussion."""
    lines = [
        *_introduction(plan, command_line),
        *_policy_lines(plan),
        *_result_tables(plan, summaries),
        *_merged_section(by_run),
        *_figure_links(written, out_md),
        "## Discussion",
        "",
        *discussion(summaries),
        "",
    ]
    return "\n".join(lines)


def _introduction(plan: ReportPlan, command_line: str) -> list[str]:
    """The title and how the document was made: the command, the grid, the conventions."""
    n_eps = len(plan.seeds) * len(plan.levels)
    return [
        "# Results",
        "",
        f"Generated by `{command_line}`; do not edit by hand. Each grid run is "
        f"{n_eps} episodes (seeds {', '.join(map(str, plan.seeds))} x traffic levels "
        f"{', '.join(str(float(x)) for x in plan.levels)}; the paper: 5 seeds x 5 levels = 25). "
        "Rows marked *(paper)* are the paper's reported values; "
        "metric definitions are in `explaindrive.env.metrics` and the aggregation conventions "
        "in `explaindrive.evaluation.aggregate` (see `docs/evaluation.md`).",
        "",
    ]


def _policy_lines(plan: ReportPlan) -> list[str]:
    """The Policies section: one line saying what each policy is."""
    lines = ["## Policies", ""]
    for name, spec in plan.policies.items():
        card = _card(spec)
        if spec.kind == "agent":
            trained = f", trained {card['episodes']} episodes" if "episodes" in card else ""
            what = f"D3QN agent `{Path(spec.paths[0]).name}`{trained}"
        elif spec.kind == "merged":
            what = "fast and comfort agents switched by the passenger command"
        else:
            what = f"SUMO {name.upper()} car-following drives the ego (SUMO safety on)"
        lines.append(f"- **{name}**: {what}")
    return [*lines, ""]


def _result_tables(plan: ReportPlan, summaries: Mapping[str, RunSummary]) -> list[str]:
    """The paper's table, per traffic level, safety, and the runs with stop injections."""
    grid = [s for name, s in summaries.items() if name != MERGED]
    plain = [summaries[n] for n in plan.policies if n in summaries]
    agents = [summaries[n] for n in plan.policies if n in AGENTS and n in summaries]
    stop_runs = [s for name, s in summaries.items() if name.endswith("+ stops")]
    lines = [
        "## Ride quality (outside STOP)",
        "",
        tables.ride_table(grid),
        "",
        "What a passenger feels, the same definitions for every driver "
        "(`src/explaindrive/env/ride_quality.py`): free road has no vehicle within 50 m and "
        "no red or yellow light or busy crossing within 60 m; a hard brake is a 1 s step "
        "braking at 3 m/s^2 or more; a reversal is an acceleration of at least 2 m/s^2 "
        "against the previous one while following a vehicle within 50 m.",
        "",
        "## The paper's table",
        "",
        tables.paper_table(plain),
        "",
    ]
    if agents:
        lines += ["## Per traffic level (paper in parentheses)", "",
                  tables.level_table(agents), ""]  # fmt: skip
    lines += [
        "## Safety, stops and travel time (not reported by the paper)",
        "",
        tables.safety_table(grid),
        "",
        f"Stop runs inject STOP at {PAPER_STOP_SCHEDULE} s. Stop latency: steps from the stop "
        "command to 0 m/s; an unfinished stop ended (or the episode ended) before standstill.",
        "",
    ]
    if stop_runs:
        lines += ["## With stop injections", "", tables.paper_table(stop_runs, False), ""]
    return lines


def _merged_section(by_run: Mapping[str, list[EpisodeRecord]]) -> list[str]:
    """The merged controller's single episode, if it was run."""
    if MERGED not in by_run:
        return []
    rec = by_run[MERGED][0]
    r = rec.result
    return [
        "## Merged controller, single episode",
        "",
        f"Commands `{PAPER_MERGED_COMMANDS}`, seed {rec.spec.seed}, traffic level "
        f"{rec.spec.traffic_level:g}: {r.steps} steps, mean speed {r.mean_speed_mps:.3f} m/s, "
        f"stop latencies {list(r.stop_latencies)} steps, collisions {r.collisions}.",
        "",
    ]


def _figure_links(written: Sequence[Path], out_md: Path) -> list[str]:
    """The Figures section: each figure, linked relative to the document."""
    if not written:
        return []
    lines = ["## Figures", ""]
    for path in written:
        lines += [f"![{path.stem}]({_rel(path, out_md)})", ""]
    return lines


def _compare(label: str, ours: float | None, paper: float | None, unit: str) -> str | None:
    rel = relative_difference(ours, paper)
    if rel is None or ours is None or paper is None:
        return None
    verdict = "close to" if abs(rel) < CLOSE_REL else ("above" if rel > 0 else "below")
    return f"{label} {ours:.3f} {unit} vs {paper:.3f} ({rel:+.0%}, {verdict} the paper)"


WHY_NUMBERS_DIFFER: tuple[str, ...] = (
    "- The scenario is a reconstruction from the paper's text: road lengths, signal plans, "
    "speed-limit zones, pedestrian flows and the exact demand pattern are ours, so absolute "
    "step counts (which scale with route length) and speeds are not expected to match; the "
    "trends over traffic levels and between the policies are the comparable part.",
    "- The paper does not define how TH and TTC are averaged. Ours average over steps with a "
    "real leader in sensor range and the ego moving at >= 1 m/s (TH) and over closing-in "
    "steps with TTC < "
    f"{TTC_INTERACTION_S:g} s (TTC), per episode, then over episodes; another convention "
    "moves these columns substantially.",
    "- Training budgets are listed under Policies (the paper trains 11,000 episodes with a "
    "5M replay buffer), and D3QN results vary between training seeds.",
    "- The SUMO baselines drive with SUMO's own safety model and are not in the paper; they "
    "are a reference for what the scenario allows, not a reproduction target. Every driver's "
    "pedestrian-yield violations are counted by the same rule: crossing the stop line while "
    "a pedestrian is in, or within a second of stepping into, the car's own lane; SUMO's "
    "cars creep over the line at a zebra as a pedestrian steps off the kerb.",
    "- Our networks are trained to keep a kinematic safety rule (safe learning, "
    "`docs/agent.md`) and drive through the merged controller's shield built on the same "
    "rule (`agent/shield.py`), neither of which the paper has; `explaindrive evaluate fast "
    "--no-shield` measures the bare networks, and the Safety shield section below gives how "
    "often the shield acted. Our mean headways are long partly because the rule keeps a "
    "stopping distance behind a leader that might brake at 9 m/s^2.",
)
"""The structural reasons our numbers and the paper's can differ (the discussion's end)."""


def discussion(summaries: Mapping[str, RunSummary]) -> list[str]:
    """Bullet points comparing our numbers with the paper's, computed from the numbers,
    followed by the structural reasons they can differ."""
    out: list[str] = []
    for name, paper in PAPER_RESULTS.items():
        if (s := summaries.get(name)) is not None:
            out += _paper_comparison(name, s, paper)
    out += _ordering_line(summaries.get("fast"), summaries.get("comfort"))
    for name in BASELINES:
        if (s := summaries.get(name)) is not None:
            out.append(_baseline_line(name, s))
    return [*out, "", "Why the numbers can differ:", "", *WHY_NUMBERS_DIFFER]


def _paper_comparison(name: str, s: RunSummary, paper: PaperRow) -> list[str]:
    """One policy against its row of the paper: overall figures, then the trend over levels."""
    o = s.overall
    parts = [
        _compare("mean speed", o.mean_speed_mps, paper.mean_speed_mps, "m/s"),
        _compare("avg TH", o.avg_headway_s, paper.avg_headway_s, "s"),
        _compare("avg TTC", o.avg_ttc_s, paper.avg_ttc_s, "s"),
        _compare("avg jerk", o.avg_jerk_mps3, paper.avg_jerk_mps3, "m/s^3"),
    ]
    coll = f"{o.collision_episodes}/{o.episodes} collision episodes vs {paper.collisions}/25"
    out = [f"- **{name}**: " + "; ".join([p for p in parts if p] + [coll]) + "."]
    levels = [x for x in sorted(s.by_level) if x in paper.steps_by_level]
    if len(levels) >= 2:
        lo, hi = levels[0], levels[-1]
        out.append(
            f"  Steps go from {s.by_level[lo].steps_mean:.0f} at level {lo:g} to "
            f"{s.by_level[hi].steps_mean:.0f} at {hi:g} (paper {paper.steps_by_level[lo]} -> "
            f"{paper.steps_by_level[hi]}); speeds fall from {s.by_level[lo].mean_speed_mps:.2f}"
            f" to {s.by_level[hi].mean_speed_mps:.2f} m/s (paper "
            f"{paper.speed_by_level_mps[lo]:.2f} -> {paper.speed_by_level_mps[hi]:.2f})."
        )
    return out


def _ordering_line(fast: RunSummary | None, comfort: RunSummary | None) -> list[str]:
    """Whether fast drives faster and comfort keeps longer headways, as in the paper."""
    if not (fast and comfort):
        return []
    faster = fast.overall.mean_speed_mps > comfort.overall.mean_speed_mps
    th_f, th_c = fast.overall.avg_headway_s, comfort.overall.avg_headway_s
    longer = th_f is not None and th_c is not None and th_c > th_f
    return [
        "- The paper's ordering (fast drives faster, comfort keeps longer headways) is "
        f"{'reproduced' if faster else 'not reproduced'} for speed and "
        f"{'reproduced' if longer else 'not reproduced'} for headway."
    ]


def _baseline_line(name: str, s: RunSummary) -> str:
    """A SUMO baseline's figures (the paper has none to compare with)."""
    o = s.overall
    return (
        f"- **{name}** (SUMO, not in the paper): mean speed {o.mean_speed_mps:.3f} m/s, "
        f"{o.collision_episodes}/{o.episodes} collision episodes, {o.red_light_runs} "
        f"red-light runs, {o.ped_violations} pedestrian-yield violations."
    )
