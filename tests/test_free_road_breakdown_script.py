"""scripts/free_road_breakdown.py: the classes of free-road steps and the split by limit."""

from __future__ import annotations

from .helpers import load_script


def _step(v: float, before: float, limit: float) -> dict:
    return {"v": v, "before": before, "limit": limit, "light": "no light in range",
            "leader": "no vehicle"}  # fmt: skip


def test_steps_fall_in_one_class_each() -> None:
    kind = load_script("free_road_breakdown").kind
    limit = 50 / 3.6  # 13.89 m/s: cruising from 12.5 m/s
    assert kind(_step(12.5, 12.5, limit)) == "cruise"
    assert kind(_step(10.0, 9.0, limit)) == "accelerating"
    assert kind(_step(10.0, 11.0, limit)) == "slowing"
    assert kind(_step(10.0, 10.4, limit)) == "steady below 90 %"


def test_the_slow_share_is_split_by_the_limit_to_the_nearest_10_kmh() -> None:
    script = load_script("free_road_breakdown")
    steps = [
        _step(8.0, 8.0, 50 / 3.6),  # 58 % of 13.89: slow
        _step(9.0, 9.0, 50 / 3.6),  # 65 %
        _step(11.0, 11.0, 70 / 3.6),  # 57 % of 19.44: slow
        _step(11.0, 11.0, 68 / 3.6),  # 58 % of 18.89, counted at 70 km/h: slow
        _step(3.0, 3.0, 20 / 3.6),  # 54 % of 5.56: slow
    ]
    assert script.by_limit(steps) == {20: (1, 1), 50: (1, 2), 70: (2, 2)}
