"""The ego's sensors against a fake simulation: values computed by hand."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.perception import (
    CrossingReading,
    CrossingSensor,
    Leader,
    LeaderSensor,
    LightReading,
    SignalLink,
    cluster_onward,
    effective_leader,
    light_ahead,
    observation,
    signal_links,
)
from explaindrive.sim.crossing_lanes import CrossingLane
from explaindrive.sim.pedestrians import KerbYield
from explaindrive.sim.route import RouteCrossing
from tests.env.fake_sumo import FakeSumo, ego_results

# a joined cluster C (two stop lines 37 m apart), then the light J2 far on
LINKS = (("C", 6, 60.0, "G"), ("C", 16, 97.0, "r"), ("J2", 1, 360.0, "r"))
ZEBRA = RouteCrossing(":Z_c0", (":Z_w0",), 250.0, signalized=False, end_m=262.0)
SIGNAL = RouteCrossing(":J1_c0", (":J1_w0",), 100.0, signalized=True, end_m=112.0)
# the ego lane runs from 3 m to 6 m along a 10 m crossing laid out west to east
LANE = CrossingLane(((0.0, 0.0), (10.0, 0.0)), 3.0, 6.0)


def test_the_real_leader_gap_adds_the_ego_min_gap_and_lengths_are_read_once() -> None:
    api = FakeSumo(vehicles={"car": (4.5, 7.0)})
    sensor = LeaderSensor(ego_min_gap_m=2.5, lengths={})
    for _ in range(2):
        assert sensor(api, ego_results(10.0, ("car", 12.0)), ()) == Leader(14.5, 7.0, 4.5, False)
    assert api.length_reads == 1
    assert sensor(api, ego_results(10.0), ()) is None  # nobody ahead
    assert sensor(api, ego_results(10.0, ("car", 197.5)), ()) is None  # 200 m: out of range
    assert sensor(api, ego_results(10.0, ("car", -4.0)), ()).gap_m == 0.0  # overlap reads as 0


def test_the_light_ahead_is_the_nearest_link_of_the_ego_with_its_own_signal() -> None:
    links = signal_links(FakeSumo(links=LINKS))
    assert links[1] == SignalLink("C", 16, 97.0, "r")
    assert light_ahead(links) == LightReading(60.0, S.LightState.GREEN, ("C", 6))
    # past C's first stop line: its second, with its own signal (index 16 of programme C)
    assert light_ahead(links[1:]) == LightReading(97.0, S.LightState.RED, ("C", 16))
    assert light_ahead(links[2:]) == LightReading()  # J2 at 360 m: beyond sensor range
    assert light_ahead(()) == LightReading()


def test_the_later_stop_lines_of_the_nearest_links_programme_are_read_on() -> None:
    links = signal_links(FakeSumo(links=LINKS))
    # C's second line (red, 97 m); J2 is another programme, and beyond range besides
    assert cluster_onward(links) == [(("C", 16), S.LightState.RED, 97.0)]
    assert cluster_onward(links[1:]) == []  # past C: J2 alone is ahead
    assert cluster_onward(()) == []


def test_a_pedestrian_in_the_ego_lane_makes_the_crossing_busy() -> None:
    people = {"p": (4.0, 0.0, 90.0, 1.2, ":Z_c0"), "q": (9.0, 0.0, 90.0, 1.2, ":Z_c0")}
    sensor = CrossingSensor((SIGNAL, ZEBRA), {":Z_c0": LANE, ":J1_c0": LANE})
    kerb = KerbYield()
    on = sensor(FakeSumo(persons={":Z_c0": ("p",)}, people=people), 240.0, kerb)
    assert on == CrossingReading(10.0, {":Z_c0": True})  # 10 m ahead, p at 4 m is in the lane
    past = sensor(FakeSumo(persons={":Z_c0": ("q",)}, people=people), 240.0, kerb)
    assert past == CrossingReading(10.0, {":Z_c0": False})  # q at 9 m has left the lane
    far = sensor(FakeSumo(persons={":Z_c0": ("p",)}, people=people), 200.0, kerb)
    assert far == CrossingReading(50.0, {":Z_c0": False})  # beyond 25 m: busy, not judged
    standing = sensor(FakeSumo(persons={":Z_c0": ("p",)}, people=people), 255.0, kerb)
    assert standing.gap_m == 0.0  # the ego's front is on the crossing
    assert sensor(FakeSumo(people=people), 240.0, kerb).gap_m == S.SENSOR_RANGE_M


def test_at_a_zebra_a_pedestrian_stepping_on_counts_and_not_at_a_light() -> None:
    people = {"w": (0.0, 0.0, 90.0, 1.2, ":Z_c0"), "s": (0.0, 0.0, 90.0, 1.2, ":J1_c0")}
    sensor = CrossingSensor((SIGNAL, ZEBRA), {":Z_c0": LANE, ":J1_c0": LANE})
    api = FakeSumo(persons={":Z_w0": ("w",), ":J1_w0": ("s",)}, people=people)
    assert sensor(api, 240.0, KerbYield()).gap_m == 10.0  # the zebra's walker
    assert sensor(api, 90.0, KerbYield()).gap_m == 160.0  # the light's is waiting


@pytest.mark.parametrize(
    ("real", "line", "crossing", "want"),
    [
        (Leader(30.0, 5.0, 4.0, False), True, 200.0, Leader(20.0, 0.0, 0.0, True)),
        (Leader(30.0, 5.0, 4.0, False), False, 200.0, Leader(30.0, 5.0, 4.0, False)),
        (Leader(10.0, 5.0, 4.0, False), True, 15.0, Leader(10.0, 5.0, 4.0, False)),
        (None, True, 15.0, Leader(15.0, 0.0, 0.0, True)),
        (None, False, 200.0, None),
    ],
)
def test_the_effective_leader_is_the_nearest(
    real: Leader | None, line: bool, crossing: float, want: Leader | None
) -> None:
    assert effective_leader(real, line, 20.0, crossing) == want


def test_the_observation_is_clipped_to_the_state_bounds() -> None:
    leader = Leader(12.0, 4.0, 4.5, False)
    light = LightReading(80.0, S.LightState.RED, "J1")
    obs = observation(Command.STOP, 25.0, 13.89, leader, light, 200.0)
    assert obs.dtype == np.float32
    np.testing.assert_allclose(obs, [2, 20, 13.89, 12, 20, 80, 2, 200], rtol=1e-6)
    free = observation(Command.FAST, 8.0, 13.89, None, LightReading(), 200.0)
    np.testing.assert_allclose(free, [0, 8, 13.89, 200, 0, 200, 0, 200], rtol=1e-6)
