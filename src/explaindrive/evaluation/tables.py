"""Markdown tables: the paper's layout, with the paper's numbers next to ours."""

from __future__ import annotations

from collections.abc import Sequence

from explaindrive.env.metrics import EpisodeResult
from explaindrive.evaluation.aggregate import Aggregate, RunSummary
from explaindrive.evaluation.paper import PaperRow, paper_row

DASH = "–"


def fmt(value: float | int | None, digits: int = 3) -> str:
    """A number for a table cell (``–`` for missing)."""
    if value is None:
        return DASH
    if isinstance(value, int):
        return str(value)
    return f"{value:.{digits}f}"


def _row(cells: Sequence[str]) -> str:
    return "| " + " | ".join(cells) + " |"


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = [_row(header), _row(["---"] * len(header))]
    lines += [_row(r) for r in rows]
    return "\n".join(lines)


def _steps_cell(by_level: dict[float, Aggregate], levels: Sequence[float]) -> str:
    return "/".join(fmt(by_level[x].steps_mean, 0) if x in by_level else DASH for x in levels)


def _levels(summaries: Sequence[RunSummary]) -> list[float]:
    return sorted({x for s in summaries for x in s.by_level})


def paper_table(summaries: Sequence[RunSummary], with_paper: bool = True) -> str:
    """The paper's results table: one row per run, followed by the paper's row if it has one."""
    levels = _levels(summaries)
    header = [
        "policy", f"steps ({'/'.join(str(float(x)) for x in levels)})", "mean speed m/s",
        "avg TH s", "avg TTC s", "avg jerk m/s^3", "AV collisions",
    ]  # fmt: skip
    rows: list[list[str]] = []
    for s in summaries:
        o = s.overall
        rows.append([
            s.name, _steps_cell(s.by_level, levels), fmt(o.mean_speed_mps), fmt(o.avg_headway_s),
            fmt(o.avg_ttc_s), fmt(o.avg_jerk_mps3), f"{o.collision_episodes}/{o.episodes}",
        ])  # fmt: skip
        paper = paper_row(s.name) if with_paper else None
        if paper is not None:
            rows.append(_paper_cells(paper, levels))
    return markdown_table(header, rows)


def _paper_cells(p: PaperRow, levels: Sequence[float]) -> list[str]:
    steps = "/".join(str(p.steps_by_level[x]) if x in p.steps_by_level else DASH for x in levels)
    return [
        f"{p.policy} (paper)", steps, fmt(p.mean_speed_mps), fmt(p.avg_headway_s),
        fmt(p.avg_ttc_s), fmt(p.avg_jerk_mps3), f"{p.collisions}/{p.episodes}",
    ]  # fmt: skip


def level_table(summaries: Sequence[RunSummary]) -> str:
    """Per traffic level: steps and mean speed of each run, the paper's in parentheses."""
    levels = _levels(summaries)
    header = ["traffic level"]
    for s in summaries:
        header += [f"{s.name} steps", f"{s.name} speed m/s"]
    rows = []
    for x in levels:
        cells = [str(float(x))]
        for s in summaries:
            agg = s.by_level.get(x)
            paper = paper_row(s.name)
            ps = paper.steps_by_level.get(x) if paper else None
            pv = paper.speed_by_level_mps.get(x) if paper else None
            steps = fmt(agg.steps_mean, 0) if agg else DASH
            speed = fmt(agg.mean_speed_mps) if agg else DASH
            cells += [
                steps + (f" ({ps})" if ps is not None else ""),
                speed + (f" ({pv:.3f})" if pv is not None else ""),
            ]
        rows.append(cells)
    return markdown_table(header, rows)


def safety_table(summaries: Sequence[RunSummary]) -> str:
    """The measures the paper does not report: rule violations, stops and travel time."""
    header = [
        "policy", "episodes", "red-light runs", "ped-yield violations", "yield violations",
        "speeding steps (share)",
        "stops done", "stop latency mean/max steps", "over ceil(v/3)+2", "unfinished stops",
        "arrived",
        "travel time s",
    ]  # fmt: skip
    rows = []
    for s in summaries:
        o = s.overall
        rows.append([
            s.name, str(o.episodes), str(o.red_light_runs), str(o.ped_violations),
            str(o.yield_violations), f"{o.speeding_steps} ({100 * o.speeding_share:.1f}%)",
            str(o.stops),
            f"{fmt(o.stop_latency_mean_steps, 2)}/{fmt(o.stop_latency_max_steps)}",
            str(o.stop_bound_misses), str(o.unfinished_stops), f"{o.arrived}/{o.episodes}",
            fmt(o.travel_time_mean_s, 1),
        ])  # fmt: skip
    return markdown_table(header, rows)


SITE_HEADERS: dict[str, str] = {
    "signal": "at a signal", "yield_junction": "at a junction without signal",
    "crossing": "at a crossing without signal", "free_road": "on the free road",
}  # fmt: skip
"""Column header of each site (:data:`~explaindrive.env.metrics.SITES`)."""


def site_table(summaries: Sequence[RunSummary]) -> str:
    """Where the violations happened: per site, collisions / red-light runs / pedestrian-yield
    violations / yield violations / speeding steps (the order of
    :data:`~explaindrive.env.metrics.VIOLATION_KINDS`; ``n/a`` for a run with no split by
    site)."""
    header = [
        "policy (collisions / red-light / ped-yield / yield / speeding)",
        *SITE_HEADERS.values(),
    ]
    rows = []
    for s in summaries:
        by_site = s.overall.violations_by_site
        cells = [
            " / ".join(str(n) for n in by_site[site].values()) if by_site else "n/a"
            for site in SITE_HEADERS
        ]
        rows.append([s.name, *cells])
    return markdown_table(header, rows)


def ride_table(summaries: Sequence[RunSummary]) -> str:
    """What a passenger feels, outside STOP (definitions: ``env/ride_quality.py``)."""
    header = [
        "policy", "mean speed m/s", "free-road speed (share of limit)", "free road < 60 %",
        "hard brakes /episode", "hard brakes /km", "reversals /min following",
        "p95 abs(jerk) m/s^3", "steps abs(jerk) >= 3", "standstill before line: light / crossing m",
        "stops 1-5 m from line", "travel time s",
    ]  # fmt: skip
    rows = []
    for s in summaries:
        o = s.overall
        rows.append([
            s.name, fmt(o.mean_speed_mps), _pct(o.free_road_speed_share),
            _pct(o.slow_free_road_share), fmt(o.hard_brakes_per_episode, 2),
            fmt(o.hard_brakes_per_km, 2), fmt(o.reversals_per_min, 2), fmt(o.jerk_p95_mps3, 2),
            _pct(o.jerky_share),
            f"{fmt(o.light_stop_gap_mean_m, 1)} / {fmt(o.crossing_stop_gap_mean_m, 1)}",
            _pct(o.stop_gap_in_window_share), fmt(o.travel_time_mean_s, 1),
        ])  # fmt: skip
    return markdown_table(header, rows)


def _pct(share: float | None) -> str:
    return DASH if share is None else f"{100 * share:.1f} %"


def episode_table(rows: Sequence[tuple[int, float, EpisodeResult]]) -> str:
    """One line per episode: ``(seed, traffic level, result)``."""
    header = [
        "seed", "traffic level", "steps", "mean speed m/s", "avg TH s", "avg TTC s",
        "avg jerk m/s^3", "collision", "red-light runs", "ped-yield violations",
        "yield violations", "speeding steps", "stop latencies", "travel time s",
    ]  # fmt: skip
    body = [
        [
            str(seed), str(float(level)), str(r.steps), fmt(r.mean_speed_mps), fmt(r.avg_headway_s),
            fmt(r.avg_ttc_s), fmt(r.avg_jerk_mps3), str(r.collisions), str(r.red_light_runs),
            str(r.ped_violations), str(r.yield_violations), str(r.speeding_steps),
            ",".join(map(str, r.stop_latencies)) or DASH, fmt(r.travel_time_s, 1),
        ]
        for seed, level, r in rows
    ]  # fmt: skip
    return markdown_table(header, body)


def shield_line(overrides: int, steps: int, applied: bool) -> str:
    """How often the safety shield replaced (or, off, would have replaced) the network."""
    share = 100.0 * overrides / steps if steps else 0.0
    verb = "replaced" if applied else "would have replaced (shield off)"
    return (
        f"Safety shield: {verb} the network's action in {overrides} of {steps} steps "
        f"({share:.2f} %)."
    )
