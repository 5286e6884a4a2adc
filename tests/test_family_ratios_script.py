"""scripts/family_ratios.py: each run beside its paper-road reference, and over Krauss's."""

from __future__ import annotations

import json
from pathlib import Path
from types import ModuleType

import pytest

from .helpers import load_script

KEYS = (
    "mean_speed_mps",
    "free_road_speed_share",
    "slow_free_road_share",
    "hard_brakes_per_episode",
    "reversals_per_min",
    "avg_jerk_mps3",
    "light_stop_gap_mean_m",
    "crossing_stop_gap_mean_m",
)


def _script() -> ModuleType:
    return load_script("family_ratios")


def _write(folder: Path, name: str, slow_share: float) -> None:
    """A run whose every figure is 1.0 but the slow free-road share."""
    overall = {key: 1.0 for key in KEYS} | {"slow_free_road_share": slow_share, "episodes": 3}
    runs = [{"aggregates": {"overall": overall}}]
    (folder / f"{name}.json").write_text(json.dumps({"runs": runs}), encoding="utf-8")


def _row(lines: list[str], label: str) -> list[str]:
    row = next(line for line in lines if line.startswith(f"| {label} |"))
    return [cell.strip() for cell in row.strip("|").split("|")][1:]


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for name, share in [
        ("road_fast", 0.10), ("road_fast_stops", 0.20), ("family_fast", 0.15),
        ("family_fast_stops", 0.25), ("road_krauss", 0.05), ("road_krauss_stops", 0.10),
        ("family_krauss", 0.06), ("family_krauss_stops", 0.15),
    ]:  # fmt: skip
        _write(tmp_path, name, share)
    return tmp_path


def test_a_run_with_stops_is_held_against_the_road_with_stops(folder: Path) -> None:
    cells = _row(_script().table(folder, "fast"), "free road < 60 %")
    # road 0.10, road with stops 0.20; family 0.15 / 0.10 = 1.5, with stops 0.25 / 0.20 = 1.25
    assert cells == ["0.100", "0.200", "0.150 (1.50)", "0.250 (1.25)"]


def test_without_the_road_with_stops_the_road_is_the_reference(folder: Path) -> None:
    (folder / "road_fast_stops.json").unlink()
    cells = _row(_script().table(folder, "fast"), "free road < 60 %")
    assert cells == ["0.100", "0.150 (1.50)", "0.250 (2.50)"]


def test_a_ratio_is_divided_by_krauss_s_on_the_same_runs(folder: Path) -> None:
    cells = _row(_script().against_krauss(folder, "fast"), "free road < 60 %")
    # family: 1.5 / (0.06 / 0.05 = 1.2) = 1.25; with stops: 1.25 / (0.15 / 0.10 = 1.5) = 0.83
    assert cells == ["1.25", "0.83"]
    assert _row(_script().against_krauss(folder, "fast"), "mean speed m/s") == ["1.00", "1.00"]


def test_no_krauss_runs_no_table(folder: Path) -> None:
    for path in folder.glob("*krauss*.json"):
        path.unlink()
    assert _script().against_krauss(folder, "fast") == []
