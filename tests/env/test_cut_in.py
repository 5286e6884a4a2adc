"""Cut-ins: a vehicle that changes into the ego's lane ahead is its leader from that step
on, and the ride-quality figures count the braking that follows.

On a straight two-lane road built by netconvert, a scripted vehicle is put in the lane
beside the ego and then told to change into the ego's lane (TraCI ``changeLane``). Every
number below is worked out by hand from the speeds: SUMO moves a car by its new speed each
1 s step, the agent ego's speed is exactly what its actions set, and the cutter is held at
6 m/s with its own lane changes off.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from explaindrive.env import state as S
from explaindrive.env.actions import action_index
from explaindrive.env.metrics import EpisodeMetrics
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.sim.scenario.files import EGO_ID
from tests.conftest import NO_DEMAND, plain_net

NODES = """<nodes>
  <node id="A" x="0" y="0" type="priority"/>
  <node id="B" x="800" y="0" type="priority"/>
  <node id="C" x="1000" y="0" type="priority"/>
</nodes>"""
EDGES = """<edges>
  <edge id="AB" from="A" to="B" numLanes="2" speed="13.89"/>
  <edge id="BC" from="B" to="C" numLanes="2" speed="13.89"/>
</edges>"""
CUTTER = "cutter"
CUTTER_MPS = 6.0  # [m/s]
CUTTER_LENGTH_M = 5.0  # SUMO's default passenger car
AHEAD_M = 60.0  # [m] the cutter enters this far ahead of the ego's front
ENTER_STEP, CHANGE_STEP = 4, 6
# the ego: +3 m/s four times (3, 6, 9, 12 m/s), holds 12 m/s, brakes twice by 3 m/s after
# the cut-in (9, 6 m/s), then holds 6 m/s behind the cutter
CHANGES = [3, 3, 3, 3, 0, 0, 0, -3, -3, 0, 0, 0, 0, 0]


@pytest.fixture(scope="module")
def two_lane_road(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """An 800 m + 200 m straight road, two lanes a way at 13.89 m/s, and no demand."""
    folder = tmp_path_factory.mktemp("two_lane_road")
    (folder / "empty.rou.xml").write_text(NO_DEMAND)
    return plain_net(folder, "road", NODES, EDGES), folder / "empty.rou.xml"


@pytest.mark.slow
def test_a_vehicle_that_cuts_in_is_the_leader_from_that_step_and_its_braking_counts(
    make_env: Callable[..., UrbanDriveEnv], two_lane_road: tuple[Path, Path]
) -> None:
    net, demand = two_lane_road
    env = make_env(net_file=net, route=("AB", "BC"), demand_file=demand, warmup_s=0,
                   max_steps=len(CHANGES))  # fmt: skip
    env.reset(seed=0)
    api = env.sumo
    ego_lane = api.vehicle.getLaneIndex(EGO_ID)
    metrics = EpisodeMetrics()
    leads, real_gaps, true_gaps, in_lane = [], [], [], []
    for step, change in enumerate(CHANGES):
        if step == ENTER_STEP:  # beside the ego, in the other lane, 60 m ahead of its front
            api.route.add("cut", ["AB", "BC"])
            api.vehicle.add(CUTTER, "cut", departLane=str(1 - ego_lane),
                            departPos=str(api.vehicle.getLanePosition(EGO_ID) + AHEAD_M),
                            departSpeed=str(CUTTER_MPS))  # fmt: skip
            api.vehicle.setLaneChangeMode(CUTTER, 0)
            api.vehicle.setSpeedMode(CUTTER, 0)
            api.vehicle.setSpeed(CUTTER, CUTTER_MPS)
        if step == CHANGE_STEP:
            api.vehicle.changeLane(CUTTER, ego_lane, 10.0)
        obs, reward, _terminated, _truncated, info = env.step(action_index(change))
        metrics.update(info, reward)
        assert not info["collision"]
        leads.append(round(float(obs[S.D_LEAD]), 3))
        real_gaps.append(round(info["real_gap_m"], 3))
        if step >= ENTER_STEP:
            front = api.vehicle.getLanePosition(CUTTER)
            true_gaps.append(round(front - CUTTER_LENGTH_M - env.route_pos_m, 3))
            in_lane.append(api.vehicle.getLaneIndex(CUTTER) == ego_lane)
    # the cutter enters 60 m ahead of the ego's front (at 12 m/s after step 3) and does not
    # move in its insertion step: 60 - 5 (its length) - 12 = 43 m; then it closes in by
    # 12 - 6 = 6 m a step (37, 31 m); after the cut-in the ego brakes to 9 m/s (31 + 6 - 9
    # = 28 m), then to 6 m/s, the cutter's speed, which keeps the 28 m
    assert true_gaps == pytest.approx([43.0, 37.0, 31.0] + [28.0] * 7, abs=1e-3)
    assert in_lane == [False, False] + [True] * 8  # it is in the ego's lane after step 6
    # no leader while it drives beside the ego (37 m ahead, in range), the cutter from the
    # step it is in the ego's lane on: the observation and the info read the same gap
    assert leads[:CHANGE_STEP] == [S.SENSOR_RANGE_M] * CHANGE_STEP
    assert real_gaps[:CHANGE_STEP] == [float("inf")] * CHANGE_STEP
    assert leads[CHANGE_STEP:] == pytest.approx(true_gaps[2:], abs=1e-3)
    assert real_gaps[CHANGE_STEP:] == pytest.approx(true_gaps[2:], abs=1e-3)
    ride = metrics.result().ride
    # the two braking steps of 3 m/s^2 after the cut-in are hard brakes (>= 3 m/s^2); the
    # 8 steps from the cut-in on follow a vehicle within 50 m; the 6 before are free road
    assert (ride.hard_brakes, ride.following_steps, ride.free_road_steps) == (2, 8, 6)
