"""A vehicle in the other branch of a lane split: the shared stretch worked out by hand, and on
a road whose one lane forks into two (built by netconvert), a car standing at the start of the
other branch is the ego's leader, which SUMO's own leader of the ego leaves out."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from explaindrive.agent.shield import shield
from explaindrive.env import state as S
from explaindrive.env.lane_split import SIDE_BY_SIDE_M, shared_stretch_m
from explaindrive.env.urban_drive import UrbanDriveEnv
from tests.conftest import NO_DEMAND, plain_net

# W -> J one lane, J -> E two lanes: at J the lane forks into both (a turn lane opening)
NODES = """<nodes>
  <node id="W" x="-300" y="0" type="priority"/>
  <node id="J" x="0" y="0" type="priority"/>
  <node id="E" x="300" y="0" type="priority"/>
</nodes>"""
EDGES = """<edges>
  <edge id="WJ" from="W" to="J" numLanes="1" speed="13.89"/>
  <edge id="JE" from="J" to="E" numLanes="2" speed="13.89"/>
</edges>"""
CONNECTIONS = """<connections>
  <connection from="WJ" to="JE" fromLane="0" toLane="0"/>
  <connection from="WJ" to="JE" fromLane="0" toLane="1"/>
</connections>"""


def test_the_shared_stretch_ends_where_the_centre_lines_are_a_car_width_apart() -> None:
    # theirs leaves ours at 0.4 m a metre: 2 m apart at x = 5, 5 * sqrt(1.16) m along theirs
    ours, theirs = [(0.0, 0.0), (10.0, 0.0)], [(0.0, 0.0), (10.0, 4.0)]
    assert SIDE_BY_SIDE_M == 2.0
    assert shared_stretch_m(ours, theirs) == pytest.approx(5.0 * math.sqrt(1.16), abs=1e-9)
    # side by side a lane apart from the start: nothing shared; the same line: all of it
    assert shared_stretch_m(ours, [(0.0, 3.2), (10.0, 3.2)]) == 0.0
    assert shared_stretch_m(ours, ours) == pytest.approx(10.0)


@pytest.fixture(scope="module")
def fork(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("fork")
    (folder / "empty.rou.xml").write_text(NO_DEMAND)
    return plain_net(folder, "fork", NODES, EDGES, CONNECTIONS), folder / "empty.rou.xml"


@pytest.mark.slow
def test_a_car_standing_at_the_start_of_the_other_branch_is_the_leader(
    make_env: Callable[..., UrbanDriveEnv], fork: tuple[Path, Path]
) -> None:
    net, demand = fork
    env = make_env(net_file=net, route=("WJ", "JE"), demand_file=demand, warmup_s=0,
                   max_steps=60)  # fmt: skip
    obs, _info = env.reset(seed=0)
    api = env.sumo
    ours = str(api.vehicle.getNextLinks("ego")[0][4])
    other = next(str(link[4]) for link in api.lane.getLinks("WJ_0") if link[4] != ours)
    api.route.add("on", ["WJ", "JE"])
    api.vehicle.add("foe", "on", departPos="0", departSpeed="0")
    api.vehicle.moveTo("foe", other, 5.0)  # a 5 m car: its back at the branch's start
    api.vehicle.setSpeed("foe", 0.0)
    line_m = float(api.lane.getLength("WJ_0"))
    gaps = []
    for _ in range(60):
        if api.vehicle.getLaneID("foe") == other:
            assert api.vehicle.getLeader("ego", 200.0) is None  # SUMO's leader leaves it out
            back = float(api.vehicle.getLanePosition("foe")) - 5.0
            gaps.append((float(obs[S.D_LEAD]), line_m - env.route_pos_m + back))
        decision = shield(obs, np.arange(7, dtype=np.float64))  # the fastest safe change
        obs, _r, terminated, truncated, info = env.step(decision.action)
        assert not info["collision"]
        if terminated or truncated:
            break
    near = [(d, want) for d, want in gaps[1:] if want < S.SENSOR_RANGE_M]
    assert near and all(d == pytest.approx(want, abs=1e-3) for d, want in near)
    assert float(obs[S.V_EGO]) == 0.0 and 0.0 < float(obs[S.D_LEAD]) < 5.0  # held behind it
