"""The ego lane's stretch on each crossing, and who is in it."""

import pytest

from explaindrive.sim.crossing_lanes import CrossingLane, crossing_lanes
from explaindrive.sim.scenario.files import default_scenario

# A crossing drawn north to south over a two-lane road 6.4 m wide; the ego's lane is the
# southern one: offsets 3.2-6.4 m from the crossing's northern end.
LANE = CrossingLane(((0.0, 6.4), (0.0, 0.0)), 3.2, 6.4)


def test_the_shipped_zebra_holds_the_ego_lane_on_its_southern_half(tmp_path):
    scenario = default_scenario(tmp_path)
    lanes = crossing_lanes(scenario.net_file, {":PX_c0": "Z1_PX", ":J2_c0": "Z2_J2"})
    for lane in lanes.values():
        # the crossing runs from y = 153.2 to 146.8; the lane's centre is y = 148.4, 3.2 wide
        assert (lane.lo_m, lane.hi_m) == (pytest.approx(3.2), pytest.approx(6.4))


@pytest.mark.parametrize(
    ("offset", "heading", "speed", "inside"),
    [
        (4.0, 0.0, 0.0, True),  # standing in the lane
        (2.8, 0.0, 0.0, True),  # within half a body of its edge
        (0.5, -1.0, 1.3, False),  # near the far kerb, walking away
        (2.0, 1.0, 1.3, True),  # reaches the lane (2.7) within a second
        (1.0, 1.0, 1.3, False),  # 1.7 m short of it: not yet
        (2.0, -1.0, 1.3, False),  # walking away from it
        (6.6, 0.0, 0.0, True),  # at the near kerb
    ],
)
def test_who_is_in_the_lane(offset, heading, speed, inside):
    assert LANE.occupied_by(offset, heading, speed) is inside


def test_offsets_project_onto_the_crossing():
    assert LANE.offset_of(0.3, 5.0) == pytest.approx(1.4)
    assert LANE.direction() == (0.0, -1.0)


def test_unknown_edges_are_named(tmp_path):
    scenario = default_scenario(tmp_path)
    with pytest.raises(ValueError, match="nowhere"):
        crossing_lanes(scenario.net_file, {":PX_c0": "nowhere"})
