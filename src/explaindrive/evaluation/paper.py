"""The numbers the paper reports (Table of results, 25 episodes = 5 seeds x 5 traffic levels).

This is the only module that holds them; tables, the report and tests import it.
"""

from __future__ import annotations

from dataclasses import dataclass

from explaindrive.sim.scenario.limits import TRAFFIC_LEVELS

PAPER_SEEDS: tuple[int, ...] = (0, 1, 2, 3, 4)
PAPER_STOP_INTERVALS_S: tuple[tuple[float, float], ...] = ((60.0, 75.0), (150.0, 165.0))
"""Stop injections used for the "with stops" speed profiles [s from the episode start]."""
PAPER_STOP_SCHEDULE = ",".join(f"{start:g}-{end:g}" for start, end in PAPER_STOP_INTERVALS_S)
""":data:`PAPER_STOP_INTERVALS_S` as a ``--stop-schedule`` (``"60-75,150-165"``)."""
PAPER_MERGED_COMMANDS = "fast:0-90,stop:90-110,comfort:110-"
"""The merged single-episode run: fast, then stop, then comfort."""


@dataclass(frozen=True, slots=True)
class PaperRow:
    """One policy's row of the paper's results table.

    Attributes:
        policy: ``fast`` or ``comfort``.
        steps_by_level: mean SUMO steps per traffic level (keys: :data:`TRAFFIC_LEVELS`).
        speed_by_level_mps: mean speed per traffic level [m/s].
        mean_speed_mps: mean speed over the 25 episodes [m/s].
        avg_headway_s: average time headway [s].
        avg_ttc_s: average time to collision [s].
        avg_jerk_mps3: average jerk [m/s^3] (``None``: not reported).
        collisions: AV collisions.
        episodes: episodes evaluated.
    """

    policy: str
    steps_by_level: dict[float, int]
    speed_by_level_mps: dict[float, float]
    mean_speed_mps: float
    avg_headway_s: float
    avg_ttc_s: float
    avg_jerk_mps3: float | None
    collisions: int
    episodes: int


def _row(
    policy: str,
    *,
    steps: tuple[int, ...],
    speeds_mps: tuple[float, ...],
    mean_speed_mps: float,
    avg_headway_s: float,
    avg_ttc_s: float,
    avg_jerk_mps3: float | None,
) -> PaperRow:
    """A row of the paper's table: per-level values in :data:`TRAFFIC_LEVELS` order; both
    policies had no collision in 25 episodes."""
    return PaperRow(
        policy=policy,
        steps_by_level=dict(zip(TRAFFIC_LEVELS, steps, strict=True)),
        speed_by_level_mps=dict(zip(TRAFFIC_LEVELS, speeds_mps, strict=True)),
        mean_speed_mps=mean_speed_mps,
        avg_headway_s=avg_headway_s,
        avg_ttc_s=avg_ttc_s,
        avg_jerk_mps3=avg_jerk_mps3,
        collisions=0,
        episodes=25,
    )


PAPER_RESULTS: dict[str, PaperRow] = {
    "fast": _row(
        "fast", steps=(253, 323, 386, 401, 397), speeds_mps=(6.087, 4.767, 3.982, 3.825, 3.879),
        mean_speed_mps=4.508, avg_headway_s=2.998, avg_ttc_s=5.603, avg_jerk_mps3=None,
    ),
    "comfort": _row(
        "comfort", steps=(257, 333, 398, 416, 405), speeds_mps=(5.996, 4.617, 3.869, 3.699, 3.800),
        mean_speed_mps=4.396, avg_headway_s=6.373, avg_ttc_s=5.460, avg_jerk_mps3=0.205,
    ),
}  # fmt: skip


def paper_row(policy: str) -> PaperRow | None:
    """The paper's row for ``policy`` (``fast``/``comfort``), or ``None`` if it reports none."""
    return PAPER_RESULTS.get(policy)
