"""The scenario family's figures beside the paper's road, from ``scripts/evaluate_family.sh``.

    python scripts/family_ratios.py [out/family]

For each driver and each of its runs on the family (generated scenarios, the netgenerate
grid; with and without stops), every ride figure and violation count next to the same
driver's on the paper's road at the same levels, with their ratio; each network's ratios
divided by Krauss's on the same runs (how much more a figure moves than the road moves
SUMO's own driver's); and each network's mean speed as a share of Krauss's on the same
episodes.
"""

from __future__ import annotations

import functools
import json
import sys
from pathlib import Path
from typing import Any

FIGURES = (
    ("mean speed m/s", "mean_speed_mps"),
    ("free-road speed (of the limit)", "free_road_speed_share"),
    ("free road < 60 %", "slow_free_road_share"),
    ("hard brakes /episode", "hard_brakes_per_episode"),
    ("reversals /min following", "reversals_per_min"),
    ("avg jerk m/s^3", "avg_jerk_mps3"),
    ("standstill before a light m", "light_stop_gap_mean_m"),
    ("standstill before a crossing m", "crossing_stop_gap_mean_m"),
)
COUNTS = ("collision_episodes", "red_light_runs", "ped_violations", "speeding_steps",
          "stop_bound_misses")  # fmt: skip
VARIANTS = ("family_{p}", "family_{p}_stops", "grid_{p}", "grid_{p}_stops")


@functools.cache
def overall(folder: Path, name: str) -> dict[str, Any] | None:
    """The overall aggregates of run ``name``, or ``None`` if it was not run (each file
    read once: the tables compare every run with its reference)."""
    path = folder / f"{name}.json"
    if not path.is_file():
        return None
    return json.loads(path.read_text(encoding="utf-8"))["runs"][0]["aggregates"]["overall"]


def _fmt(value: float | None) -> str:
    return "–" if value is None else f"{value:.3f}"


def _ratio(value: float | None, reference: float | None) -> str:
    return _fmt_ratio(_quotient(value, reference))


def reference(folder: Path, run: str, driver: str) -> dict[str, Any] | None:
    """The paper's road's run that ``run`` of ``driver`` is compared with: the one with the
    stops for a run with stops, if it was run."""
    if run.endswith("_stops"):
        with_stops = overall(folder, f"road_{driver}_stops")
        if with_stops is not None:
            return with_stops
    return overall(folder, f"road_{driver}")


def table(folder: Path, driver: str) -> list[str]:
    """Markdown lines comparing ``driver``'s family runs with its paper-road runs."""
    road = overall(folder, f"road_{driver}")
    runs = [(v.format(p=driver), overall(folder, v.format(p=driver))) for v in VARIANTS]
    runs = [(name, a, reference(folder, name, driver)) for name, a in runs if a is not None]
    if road is None or not runs:
        return []
    roads = [(name, overall(folder, name)) for name in (f"road_{driver}", f"road_{driver}_stops")]
    roads = [(name, r) for name, r in roads if r is not None]
    head = ["figure"] + [name for name, _ in roads] + [f"{name} (ratio)" for name, _, _ in runs]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for label, key in FIGURES:
        cells = [f"{_fmt(a[key])} ({_ratio(a[key], ref[key])})" for _, a, ref in runs]
        lines.append("| " + " | ".join([label, *(_fmt(r[key]) for _, r in roads), *cells]) + " |")
    for key in COUNTS:
        cells = [str(r.get(key, "–")) for _, r in roads]
        cells += [str(a.get(key, "–")) for _, a, _ in runs]
        lines.append("| " + " | ".join([key, *cells]) + " |")
    counts = [str(r["episodes"]) for _, r in roads] + [str(a["episodes"]) for _, a, _ in runs]
    lines.append("| episodes | " + " | ".join(counts) + " |")
    return lines


def against_krauss(folder: Path, driver: str) -> list[str]:
    """Markdown lines: ``driver``'s ratio of each ride figure (a family run over the paper's
    road) divided by Krauss's ratio on the same runs."""
    pairs = []
    for variant in VARIANTS:
        run, krauss_run = variant.format(p=driver), variant.format(p="krauss")
        a, k = overall(folder, run), overall(folder, krauss_run)
        road, krauss_road = reference(folder, run, driver), reference(folder, krauss_run, "krauss")
        if a is not None and k is not None and road is not None and krauss_road is not None:
            pairs.append((run, a, road, k, krauss_road))
    if not pairs:
        return []
    head = ["figure"] + [run for run, *_ in pairs]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for label, key in FIGURES:
        cells = [
            _fmt_ratio(_quotient(_quotient(a[key], road[key]), _quotient(k[key], kroad[key])))
            for _, a, road, k, kroad in pairs
        ]
        lines.append("| " + " | ".join([label, *cells]) + " |")
    return lines


def _quotient(value: float | None, reference: float | None) -> float | None:
    if value is None or reference is None or reference == 0:
        return None
    return value / reference


def _fmt_ratio(value: float | None) -> str:
    return "–" if value is None else f"{value:.2f}"


def krauss_shares(folder: Path) -> list[str]:
    """Each network's mean speed as a share of Krauss's on the same episodes."""
    lines = []
    for where in ("road", "family", "grid"):
        krauss = overall(folder, f"{where}_krauss")
        for driver in ("fast", "comfort"):
            a = overall(folder, f"{where}_{driver}")
            if krauss and a:
                share = a["mean_speed_mps"] / krauss["mean_speed_mps"]
                speeds = f"{a['mean_speed_mps']:.3f} m/s, Krauss {krauss['mean_speed_mps']:.3f} m/s"
                lines.append(f"- {where}: {driver} {speeds}: {100 * share:.1f} %")
    return lines


def main(folder: Path) -> None:
    """Print the tables of every driver found in ``folder``."""
    for driver in ("fast", "comfort", "krauss"):
        lines = table(folder, driver)
        if lines:
            print(f"\n### {driver}\n")
            print("\n".join(lines))
    for driver in ("fast", "comfort"):
        lines = against_krauss(folder, driver)
        if lines:
            print(f"\n### {driver}: its ratios over Krauss's\n")
            print("\n".join(lines))
    shares = krauss_shares(folder)
    if shares:
        print("\n### Mean speed against Krauss\n")
        print("\n".join(shares))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/family"))
