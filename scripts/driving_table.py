"""The README's driving table from the JSON files of ``scripts/evaluate_shipped.sh``.

    python scripts/driving_table.py [out/eval]

One row per run found: the ride-quality figures first, then the violations and the share of
steps the shield would have overridden. Runs missing from the folder are skipped.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

ROWS = (
    ("fast", "fast_bare"),
    ("fast + stops", "fast_bare_stops"),
    ("fast", "fast_bare_175"),
    ("fast + stops", "fast_bare_175_stops"),
    ("fast, noise 1 m / 0.3 m/s", "fast_bare_noise_1_0.3"),
    ("fast + stops, noise 1 m / 0.3 m/s", "fast_bare_noise_1_0.3_stops"),
    ("fast, noise 2 m / 0.6 m/s", "fast_bare_noise_2_0.6"),
    ("fast, noise 3 m / 0.9 m/s", "fast_bare_noise_3_0.9"),
    ("comfort", "comfort_bare"),
    ("comfort + stops", "comfort_bare_stops"),
    ("comfort", "comfort_bare_175"),
    ("comfort + stops", "comfort_bare_175_stops"),
    ("comfort, noise 1 m / 0.3 m/s", "comfort_bare_noise_1_0.3"),
    ("comfort + stops, noise 1 m / 0.3 m/s", "comfort_bare_noise_1_0.3_stops"),
    ("comfort, noise 2 m / 0.6 m/s", "comfort_bare_noise_2_0.6"),
    ("comfort, noise 3 m / 0.9 m/s", "comfort_bare_noise_3_0.9"),
    ("fast, the paper's rewards (`--preset safe`)", "fast_paper_bare"),
    ("fast + stops, the paper's rewards", "fast_paper_bare_stops"),
    ("comfort, the paper's rewards (`--preset safe`)", "comfort_paper_bare"),
    ("comfort + stops, the paper's rewards", "comfort_paper_bare_stops"),
    ("SUMO Krauss", "krauss_bare"),
    ("SUMO Krauss + stops", "krauss_bare_stops"),
    ("SUMO Krauss", "krauss_bare_175"),
    ("SUMO Krauss + stops", "krauss_bare_175_stops"),
    ("SUMO IDM", "idm_bare"),
    ("SUMO IDM + stops", "idm_bare_stops"),
    ("SUMO IDM", "idm_bare_175"),
    ("SUMO IDM + stops", "idm_bare_175_stops"),
)
HEADER = (
    "driver", "episodes (seeds)", "mean speed m/s", "free-road speed (of the limit)",
    "free road < 60 %", "hard brakes /episode", "reversals /min following", "avg jerk m/s^3",
    "standstill before line: light / crossing m", "collisions", "red-light runs",
    "ped-yield viol.", "speeding steps", "stops over ceil(v/3)+2", "arrived",
    "shield would act",
)  # fmt: skip


def _num(value: float | None, digits: int = 3) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def _pct(share: float | None) -> str:
    return "–" if share is None else f"{100 * share:.1f} %"


def _span(values: list[int]) -> str:
    """``0-49`` for consecutive seeds, else the list."""
    if values == list(range(values[0], values[-1] + 1)) and len(values) > 2:
        return f"{values[0]}-{values[-1]}"
    return ", ".join(map(str, values))


def grid(run: dict[str, Any]) -> str:
    """The run's seeds and traffic levels, as the table names them."""
    levels = run["traffic_levels"]
    where = f"{len(levels)} levels" if len(levels) > 1 else f"traffic {levels[0]:g}"
    return f"seeds {_span(run['seeds'])} x {where}"


def row(label: str, run: dict[str, Any]) -> list[str]:
    """One table row of a run document."""
    a = run["aggregates"]["overall"]
    episodes = run["episodes"]
    steps = sum(e["metrics"]["steps"] for e in episodes)
    overrides = sum(e.get("shield_overrides", 0) for e in episodes)
    shield = "–" if run["policy"]["kind"] == "baseline" else f"{100 * overrides / steps:.2f} %"
    stops = "–" if not a["stops"] else f"{a['stop_bound_misses']} of {a['stops']}"
    gaps = f"{_num(a['light_stop_gap_mean_m'], 1)} / {_num(a['crossing_stop_gap_mean_m'], 1)}"
    return [
        label, f"{a['episodes']} ({grid(run)})", _num(a["mean_speed_mps"]),
        _pct(a["free_road_speed_share"]), _pct(a["slow_free_road_share"]),
        _num(a["hard_brakes_per_episode"], 2), _num(a["reversals_per_min"], 2),
        _num(a["avg_jerk_mps3"]), gaps, str(a["collision_episodes"]), str(a["red_light_runs"]),
        str(a["ped_violations"]), str(a["speeding_steps"]), stops,
        f"{a['arrived']}/{a['episodes']}", shield,
    ]  # fmt: skip


def main(folder: Path) -> None:
    """Print the table of every run found in ``folder``."""
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    for label, name in ROWS:
        path = folder / f"{name}.json"
        if path.is_file():
            run = json.loads(path.read_text(encoding="utf-8"))["runs"][0]
            lines.append("| " + " | ".join(row(label, run)) + " |")
    print("\n".join(lines))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/eval"))
