"""Episode metrics against hand-computed numbers."""

import math

import pytest

from explaindrive.env.metrics import EpisodeMetrics, EpisodeResult, stop_latency_bound


def info(
    speed,
    command="fast",
    *,
    headway=math.inf,
    ttc=math.inf,
    jerk=0.0,
    dist=0.0,
    t=0.0,
    collision=False,
    red=False,
    ped=False,
    yield_=False,
    speeding=False,
    arrived=False,
    site="free_road",
):
    return {
        "speed_mps": speed,
        "command": command,
        "real_headway_s": headway,
        "real_ttc_s": ttc,
        "jerk_mps3": jerk,
        "distance_m": dist,
        "time_s": t,
        "collision": collision,
        "red_light_run": red,
        "ped_violation": ped,
        "yield_violation": yield_,
        "speeding": speeding,
        "site": site,
        "arrived": arrived,
        "accel_mps2": 0.0,
        "posted_limit_mps": 13.89,
        "real_gap_m": math.inf,
        "gap_m": math.inf,
        "leader_virtual": False,
        "light_gap_m": 200.0,
        "light_state": "green",
        "crossing_gap_m": 200.0,
    }


def test_episode_figures():
    m = EpisodeMetrics()
    m.update(info(3.0, headway=2.0, ttc=4.0, jerk=3.0, dist=3, t=1), reward=1.0)
    m.update(info(6.0, headway=4.0, ttc=12.0, jerk=0.0, dist=9, t=2), reward=2.0)
    m.update(info(6.0, jerk=-3.0, dist=15, t=3, speeding=True, red=True), reward=-10.0)
    m.update(info(9.0, ttc=2.0, jerk=3.0, dist=24, t=4, arrived=True), reward=0.5)
    r = m.result()
    assert r.steps == 4
    assert r.mean_speed_mps == 6.0  # (3 + 6 + 6 + 9) / 4
    assert r.avg_headway_s == 3.0  # (2 + 4) / 2, steps without a leader skipped
    assert r.avg_ttc_s == 3.0  # (4 + 2) / 2; 12 s is no interaction (>= 10 s)
    assert r.avg_jerk_mps3 == 2.25  # (3 + 0 + 3 + 3) / 4
    assert (r.collisions, r.red_light_runs, r.ped_violations, r.speeding_steps) == (0, 1, 0, 1)
    assert r.violations == 2
    assert r.travel_time_s == 4.0 and r.distance_m == 24.0
    assert r.total_reward == pytest.approx(-6.5)


def test_violations_are_split_by_site() -> None:
    m = EpisodeMetrics()
    m.update(info(6.0, speeding=True, red=True, site="signal"))
    m.update(info(6.0, speeding=True, site="signal"))  # still speeding inside the junction
    m.update(info(5.0, ped=True, site="crossing"))
    m.update(info(5.0, collision=True, site="yield_junction"))
    m.update(info(7.0, yield_=True, site="yield_junction"))  # crossed before a foe
    m.update(info(15.0, speeding=True))
    m.update(info(12.0, site="signal"))  # a site with nothing wrong counts nothing
    r = m.result()
    assert (r.collisions, r.red_light_runs, r.ped_violations, r.yield_violations,
            r.speeding_steps) == (1, 1, 1, 1, 3)  # fmt: skip
    assert r.violations == 7  # 1 + 1 + 1 + 1 + 3
    zero = {"collisions": 0, "red_light_runs": 0, "ped_violations": 0, "yield_violations": 0,
            "speeding_steps": 0}  # fmt: skip
    assert r.violations_by_site == {
        "signal": {**zero, "red_light_runs": 1, "speeding_steps": 2},
        "yield_junction": {**zero, "collisions": 1, "yield_violations": 1},
        "crossing": {**zero, "ped_violations": 1},
        "free_road": {**zero, "speeding_steps": 1},
    }
    assert EpisodeResult.from_dict(r.as_dict()) == r
    old = r.as_dict()
    del old["violations_by_site"]  # a file written before sites were recorded
    assert EpisodeResult.from_dict(old).violations_by_site == {}
    # a file written before yield violations were counted: none, at every site
    older = r.as_dict()
    del older["yield_violations"]
    for counts in older["violations_by_site"].values():
        del counts["yield_violations"]
    read = EpisodeResult.from_dict(older)
    assert read.yield_violations == 0 and read.violations == 6
    assert read.violations_by_site["yield_junction"] == {**zero, "collisions": 1}
    assert list(read.violations_by_site["signal"]) == list(zero)  # the kinds' order


def test_stop_latency_counts_steps_to_standstill():
    m = EpisodeMetrics()
    for speed, cmd in [
        (9, "fast"),
        (6, "stop"),
        (3, "stop"),
        (0, "stop"),
        (0, "stop"),
        (2, "fast"),
        (1, "stop"),
        (1, "comfort"),
    ]:
        m.update(info(float(speed), cmd))
    r = m.result()
    assert r.stop_latencies == (3,)
    assert r.stop_bound_misses == 0  # 3 steps <= ceil(9 / 3) + 2 = 5
    assert r.unfinished_stops == 1  # the second stop was lifted before standstill


def test_slow_stop_misses_its_bound():
    m = EpisodeMetrics()
    # STOP at 6 m/s: bound ceil(6 / 3) + 2 = 4 steps; it takes 5
    for speed, cmd in [
        (6, "fast"),
        (5, "stop"),
        (4, "stop"),
        (3, "stop"),
        (2, "stop"),
        (0, "stop"),
    ]:
        m.update(info(float(speed), cmd))
    r = m.result()
    assert r.stop_latencies == (5,) and r.stop_bound_misses == 1
    assert r.travel_time_s is None


def test_empty_episode():
    r = EpisodeMetrics().result()
    assert (r.steps, r.mean_speed_mps, r.avg_headway_s, r.avg_ttc_s) == (0, 0.0, None, None)


@pytest.mark.parametrize(("speed", "bound"), [(0.0, 2), (3.0, 3), (13.0, 7), (13.89, 7)])
def test_stop_latency_bound(speed, bound):
    assert stop_latency_bound(speed) == bound
