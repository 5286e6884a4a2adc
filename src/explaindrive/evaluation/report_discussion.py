"""The discussion of ``docs/results.md``: our numbers against the paper's, in words.

:func:`discussion` compares each policy's overall figures and its trend over traffic levels
with the paper's row, says whether the paper's ordering of fast and comfort holds, gives the
SUMO baselines' figures, and ends with the structural reasons the numbers can differ.
"""

from __future__ import annotations

from collections.abc import Mapping

from explaindrive.env.metrics import TTC_INTERACTION_S
from explaindrive.evaluation.aggregate import RunSummary, relative_difference
from explaindrive.evaluation.paper import PAPER_RESULTS, PaperRow
from explaindrive.evaluation.spec import BASELINES

CLOSE_REL = 0.10  # relative difference under which a figure is called close to the paper's


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
        f"red-light runs, {o.ped_violations} pedestrian-yield violations, "
        f"{o.yield_violations} yield violations."
    )
