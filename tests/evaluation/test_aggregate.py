"""Aggregation maths against hand-computed numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from explaindrive.env.metrics import EpisodeResult
from explaindrive.evaluation.aggregate import (
    RunSummary,
    aggregate,
    aggregate_by_level,
    command_spans,
    relative_difference,
    speed_band,
)
from explaindrive.evaluation.tables import level_table, paper_table


def result(**kw: object) -> EpisodeResult:
    base: dict[str, object] = dict(
        steps=100, mean_speed_mps=5.0, avg_headway_s=None, avg_ttc_s=None, avg_jerk_mps3=0.0,
        collisions=0, red_light_runs=0, ped_violations=0, speeding_steps=0, stop_latencies=(),
        unfinished_stops=0, stop_bound_misses=0, distance_m=500.0, travel_time_s=None,
        total_reward=0.0,
    )  # fmt: skip
    base.update(kw)
    return EpisodeResult(**base)  # type: ignore[arg-type]


A = result(steps=100, mean_speed_mps=4.0, avg_headway_s=2.0, avg_ttc_s=3.0, avg_jerk_mps3=0.2,
           speeding_steps=10, stop_latencies=(2, 4), travel_time_s=100.0)  # fmt: skip
B = result(steps=200, mean_speed_mps=6.0, avg_headway_s=None, avg_ttc_s=5.0, avg_jerk_mps3=0.4,
           collisions=1, red_light_runs=2, ped_violations=1, stop_latencies=(6,),
           unfinished_stops=1, stop_bound_misses=1)  # fmt: skip
C = result(steps=300, mean_speed_mps=8.0, avg_headway_s=4.0, avg_ttc_s=None, avg_jerk_mps3=0.6,
           speeding_steps=20, travel_time_s=300.0)  # fmt: skip


def test_aggregate_by_hand() -> None:
    agg = aggregate([A, B, C])
    assert agg.episodes == 3
    assert agg.steps_mean == pytest.approx(200.0)
    assert agg.steps_std == pytest.approx(math.sqrt((100**2 + 0 + 100**2) / 3))  # 81.65
    assert agg.mean_speed_mps == pytest.approx(6.0)
    assert agg.mean_speed_std == pytest.approx(math.sqrt(8 / 3))
    assert (agg.avg_headway_s, agg.headway_episodes) == (pytest.approx(3.0), 2)  # A, C
    assert (agg.avg_ttc_s, agg.ttc_episodes) == (pytest.approx(4.0), 2)  # A, B
    assert agg.avg_jerk_mps3 == pytest.approx(0.4)
    assert agg.collision_episodes == 1
    assert (agg.red_light_runs, agg.ped_violations) == (2, 1)
    assert agg.speeding_steps == 30 and agg.speeding_share == pytest.approx(30 / 600)
    assert (agg.stops, agg.unfinished_stops, agg.stop_bound_misses) == (3, 1, 1)
    assert agg.stop_latency_mean_steps == pytest.approx(4.0)  # (2 + 4 + 6) / 3
    assert agg.stop_latency_max_steps == 6
    assert (agg.arrived, agg.travel_time_mean_s) == (2, pytest.approx(200.0))


def test_groups_by_level_and_rejects_empty() -> None:
    groups = aggregate_by_level([(1.0, C), (0.5, A), (1.0, B)])
    assert list(groups) == [0.5, 1.0]
    assert groups[0.5].steps_mean == 100.0 and groups[1.0].steps_mean == 250.0
    assert groups[1.0].mean_speed_mps == pytest.approx(7.0)
    one = aggregate([B])
    assert one.avg_headway_s is None and one.stop_latency_max_steps == 6 and one.steps_std == 0.0
    with pytest.raises(ValueError, match="empty"):
        aggregate([])


def test_speed_band_counts_running_episodes() -> None:
    band = speed_band([[1.0, 3.0, 5.0], [3.0, 5.0]])
    np.testing.assert_allclose(band.time_s, [1.0, 2.0, 3.0])
    np.testing.assert_allclose(band.mean_mps, [2.0, 4.0, 5.0])
    np.testing.assert_allclose(band.std_mps, [1.0, 1.0, 0.0])
    np.testing.assert_array_equal(band.count, [2, 2, 1])
    with pytest.raises(ValueError):
        speed_band([[]])


def test_command_spans_and_relative_difference() -> None:
    spans = command_spans(["fast", "fast", "stop", "comfort", "comfort"])
    assert spans == [("fast", 0.0, 2.0), ("stop", 2.0, 3.0), ("comfort", 3.0, 5.0)]
    assert relative_difference(5.0, 4.0) == pytest.approx(0.25)
    assert relative_difference(None, 4.0) is None and relative_difference(1.0, 0.0) is None


def test_tables_show_ours_next_to_the_paper() -> None:
    s = RunSummary("fast", aggregate([A, B]), aggregate_by_level([(0.5, A), (1.0, B)]))
    table = paper_table([s])
    lines = table.splitlines()
    assert lines[0].startswith("| policy | steps (0.5/1.0) |")
    assert lines[2] == "| fast | 100/200 | 5.000 | 2.000 | 4.000 | 0.300 | 1/2 |"
    assert lines[3] == "| fast (paper) | 253/386 | 4.508 | 2.998 | 5.603 | – | 0/25 |"
    per_level = level_table([s]).splitlines()
    assert per_level[2] == "| 0.5 | 100 (253) | 4.000 (6.087) |"
    assert per_level[3] == "| 1.0 | 200 (386) | 6.000 (3.982) |"


def test_discussion_is_computed_from_the_numbers() -> None:
    from explaindrive.evaluation.report_discussion import discussion

    fast = RunSummary("fast", aggregate([A]), aggregate_by_level([(0.5, A)]))
    comfort = RunSummary("comfort", aggregate([C]), aggregate_by_level([(0.5, C)]))
    text = "\n".join(discussion({"fast": fast, "comfort": comfort}))
    # fast: 4.0 vs 4.508 m/s is -11 %; TH 2.0 vs 2.998 s is -33 %
    assert "mean speed 4.000 m/s vs 4.508 (-11%, below the paper)" in text
    assert "avg TH 2.000 s vs 2.998 (-33%, below the paper)" in text
    assert "0/1 collision episodes vs 0/25" in text
    # comfort (8 m/s) is faster than fast (4 m/s): the ordering is not reproduced for speed
    assert "is not reproduced for speed and reproduced for headway" in text


def test_speed_panels_take_each_run_its_own_traces() -> None:
    from types import SimpleNamespace

    from explaindrive.evaluation.report import _speed_panels

    plan = SimpleNamespace(policies={"fast": None, "krauss": None})
    by_run = {
        "fast": [SimpleNamespace(speeds_mps=(5.0, 6.0))],
        "fast + stops": [SimpleNamespace(speeds_mps=(5.0, 0.0))],
        "krauss": [SimpleNamespace(speeds_mps=(7.0,))],
    }
    assert _speed_panels(plan, by_run, ("fast", "comfort")) == {  # type: ignore[arg-type]
        "fast": [(5.0, 6.0)],
        "fast + stops": [(5.0, 0.0)],
    }
    assert _speed_panels(plan, by_run, ("krauss",)) == {"krauss": [(7.0,)]}  # type: ignore[arg-type]


def test_shield_line_gives_the_share() -> None:
    from explaindrive.evaluation.tables import shield_line

    assert shield_line(3, 400, True) == (
        "Safety shield: replaced the network's action in 3 of 400 steps (0.75 %)."
    )
    assert "would have replaced (shield off)" in shield_line(0, 0, False)


def test_violations_by_site_are_summed_and_tabled() -> None:
    from explaindrive.env.metrics import no_violations_by_site
    from explaindrive.evaluation.tables import site_table

    a, b = no_violations_by_site(), no_violations_by_site()
    a["signal"]["red_light_runs"], a["free_road"]["speeding_steps"] = 2, 10
    b["signal"]["speeding_steps"], b["yield_junction"]["collisions"] = 3, 1
    b["crossing"]["ped_violations"] = 1
    a["yield_junction"]["yield_violations"], b["yield_junction"]["yield_violations"] = 2, 1
    agg = aggregate([result(violations_by_site=a, yield_violations=2),
                     result(violations_by_site=b, yield_violations=1)])  # fmt: skip
    assert agg.yield_violations == 3
    assert agg.violations_by_site == {
        "signal": {"collisions": 0, "red_light_runs": 2, "ped_violations": 0,
                   "yield_violations": 0, "speeding_steps": 3},
        "yield_junction": {"collisions": 1, "red_light_runs": 0, "ped_violations": 0,
                           "yield_violations": 3, "speeding_steps": 0},
        "crossing": {"collisions": 0, "red_light_runs": 0, "ped_violations": 1,
                     "yield_violations": 0, "speeding_steps": 0},
        "free_road": {"collisions": 0, "red_light_runs": 0, "ped_violations": 0,
                      "yield_violations": 0, "speeding_steps": 10},
    }  # fmt: skip
    # an episode from a file written before sites were recorded: no split for the group
    assert aggregate([result(violations_by_site=a), result()]).violations_by_site == {}
    row = site_table([RunSummary("fast", agg, {})]).splitlines()[2]
    assert row == (
        "| fast | 0 / 2 / 0 / 0 / 3 | 1 / 0 / 0 / 3 / 0 | 0 / 0 / 1 / 0 / 0 | 0 / 0 / 0 / 0 / 10 |"
    )
    none = site_table([RunSummary("old", aggregate([result()]), {})]).splitlines()[2]
    assert none == "| old | n/a | n/a | n/a | n/a |"
