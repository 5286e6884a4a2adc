"""The shipping rule: violations, then the targets' relative shortfall, then the objective."""

from __future__ import annotations

from dataclasses import fields, replace

import pytest

from explaindrive.evaluation.aggregate import Aggregate
from explaindrive.evaluation.selection import (
    GRIDS,
    Candidate,
    at_least,
    at_most,
    choose_pair,
    judge,
    rank,
    targets,
    violations,
    within,
)


def figures(**values: float | int | None) -> Aggregate:
    """An aggregate with zero everywhere but ``values``."""
    base: dict[str, float | int | None] = {f.name: 0 for f in fields(Aggregate)}
    base.update(episodes=50, light_stop_gap_mean_m=None, crossing_stop_gap_mean_m=None)
    return Aggregate(**{**base, **values})  # type: ignore[arg-type]


KRAUSS = figures(mean_speed_mps=8.0, hard_brakes_per_episode=2.0, reversals_per_min=2.0)
IDM = figures(mean_speed_mps=8.0, avg_jerk_mps3=0.5)
# a comfort ride that meets every target: 7.6 = 0.95 * 8.0 m/s, jerk 0.25 = half of IDM's
GOOD_COMFORT = figures(
    mean_speed_mps=7.6, slow_free_road_share=0.10, hard_brakes_per_episode=0.5,
    avg_jerk_mps3=0.25, light_stop_gap_mean_m=3.0, crossing_stop_gap_mean_m=5.0,
)  # fmt: skip
GOOD_FAST = figures(mean_speed_mps=8.0, hard_brakes_per_episode=2.0, reversals_per_min=2.0)


def cand(
    name: str, mode: str, ride: Aggregate, rule: str = "gentle", **grids: Aggregate
) -> Candidate:
    """A candidate clean on the stops and noise grids unless ``grids`` says otherwise."""
    clean = figures()
    every = {"stops": clean, "noise": clean, "heavy_noise": clean, "noise_free": ride}
    return Candidate(name, mode, rule, {**every, **grids})


def test_shortfalls_are_relative_to_the_bound() -> None:
    assert at_least("v", 9.0, 10.0).shortfall == pytest.approx(0.1)
    assert at_least("v", 11.0, 10.0).shortfall == 0.0
    assert at_most("hb", 1.5, 0.5).shortfall == pytest.approx(2.0)
    assert at_most("hb", 0.4, 0.5).shortfall == 0.0
    assert at_most("rev", 0.3, 0.0).shortfall == pytest.approx(0.3)  # a zero bound: the value
    assert within("gap", 6.0, 1.0, 5.0).shortfall == pytest.approx(0.2)
    assert within("gap", 0.5, 1.0, 5.0).shortfall == pytest.approx(0.5)
    assert within("gap", 1.0, 1.0, 5.0).shortfall == 0.0
    assert within("gap", None, 1.0, 5.0).shortfall == 0.0  # no stop of that kind


def test_comfort_targets_against_idm() -> None:
    ride = replace(
        GOOD_COMFORT, slow_free_road_share=0.12, hard_brakes_per_episode=1.0,
        light_stop_gap_mean_m=6.0, crossing_stop_gap_mean_m=4.0,
    )  # fmt: skip
    found = {t.name: t.shortfall for t in targets("comfort", ride, KRAUSS, IDM)}
    assert found == pytest.approx({
        "mean speed": 0.0, "slow free road": 0.2, "hard brakes": 1.0, "avg jerk": 0.0,
        "standstill at lights": 0.2, "standstill at crossings": 0.0,
    })  # fmt: skip
    judged = judge(cand("c", "comfort", ride), KRAUSS, IDM)
    assert judged.shortfall == pytest.approx(1.4)
    assert judged.met == 3


def test_fast_targets_against_krauss() -> None:
    ride = replace(GOOD_FAST, mean_speed_mps=7.6, reversals_per_min=0.5)
    found = {t.name: t.shortfall for t in targets("fast", ride, KRAUSS, IDM)}
    assert found == pytest.approx({"mean speed": 0.05, "hard brakes": 0.0, "reversals": 0.0})
    with pytest.raises(ValueError, match="unknown mode"):
        targets("stop", ride, KRAUSS, IDM)


def test_violations_are_summed_over_the_grids() -> None:
    a = figures(collision_episodes=1, red_light_runs=2, ped_violations=3, speeding_steps=4,
                stop_bound_misses=5, yield_violations=6)  # fmt: skip
    assert violations(a) == 21  # 1 + 2 + 3 + 4 + 5 + 6
    c = cand(
        "c", "fast", GOOD_FAST, stops=figures(speeding_steps=3),
        noise=figures(collision_episodes=1),
        heavy_noise=figures(speeding_steps=20, red_light_runs=2),  # speeding not counted
    )  # fmt: skip
    assert judge(c, KRAUSS, IDM).violations == 6
    assert violations(a, speeding=False) == 17  # 21 - 4


def test_rank_puts_violations_before_shortfall_before_objective() -> None:
    clean_but_short = cand("short", "comfort", replace(GOOD_COMFORT, hard_brakes_per_episode=2.0))
    violating = cand("speeds", "comfort", GOOD_COMFORT, noise=figures(speeding_steps=1))
    smooth = cand("smooth", "comfort", replace(GOOD_COMFORT, avg_jerk_mps3=0.20))
    rough = cand("rough", "comfort", GOOD_COMFORT)
    judged = rank([violating, clean_but_short, rough, smooth], KRAUSS, IDM)
    order = [j.candidate.name for j in judged]
    assert order == ["smooth", "rough", "short", "speeds"]
    fast_slow = cand("slow", "fast", replace(GOOD_FAST, mean_speed_mps=9.0))
    fast_quick = cand("quick", "fast", replace(GOOD_FAST, mean_speed_mps=9.5))
    judged = rank([fast_slow, fast_quick], KRAUSS, IDM)
    assert [j.candidate.name for j in judged] == ["quick", "slow"]


def test_pair_shares_a_yellow_rule_and_has_the_smallest_total_shortfall() -> None:
    fast_a = cand("fast a", "fast", replace(GOOD_FAST, mean_speed_mps=7.2), rule="gentle")  # 0.1
    fast_b = cand("fast b", "fast", replace(GOOD_FAST, mean_speed_mps=5.6), rule="decided")  # 0.3
    comfort_c = cand("comfort c", "comfort", replace(GOOD_COMFORT, hard_brakes_per_episode=1.0),
                     rule="decided")  # 1.0  # fmt: skip
    comfort_d = cand("comfort d", "comfort", replace(GOOD_COMFORT, hard_brakes_per_episode=1.25),
                     rule="gentle")  # 1.5  # fmt: skip
    pair = choose_pair([fast_a, fast_b, comfort_c, comfort_d], KRAUSS, IDM)
    assert (pair.fast.candidate.name, pair.comfort.candidate.name) == ("fast b", "comfort c")
    with pytest.raises(ValueError, match="same rule"):
        choose_pair([fast_a, comfort_c], KRAUSS, IDM)


def test_a_candidate_needs_every_grid() -> None:
    assert GRIDS == ("stops", "noise_free", "noise", "heavy_noise")
    with pytest.raises(ValueError, match="noise, heavy_noise"):
        Candidate("c", "fast", "gentle", {"stops": figures(), "noise_free": figures()})
    with pytest.raises(ValueError, match="unknown mode"):
        Candidate("c", "stop", "gentle", {g: figures() for g in GRIDS})
