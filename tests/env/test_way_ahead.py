"""The vehicles on the ego's lanes ahead, read lane by lane: gaps worked out by hand on a fake
network, and on a real one (built by netconvert) the reading agrees with SUMO's own leader
wherever SUMO reports one."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from explaindrive.env import state as S
from explaindrive.env.actions import IDLE_ACTION
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.env.way_ahead import WayAhead
from tests.conftest import NO_DEMAND, plain_net

# lane -> (length, its links: (to lane, via lane)); the ego's way: a_0 (100 m), through the
# junction on :J_0_0 (8 m, its second part :J_1_0, 4 m, after an internal junction), b_0
# (0.9 m), :K_0_0 (10 m), c_0 (150 m)
LANES: dict[str, tuple[float, tuple[tuple[str, str], ...]]] = {
    "a_0": (100.0, (("b_0", ":J_0_0"),)),
    ":J_0_0": (8.0, (("b_0", ":J_1_0"),)),
    ":J_1_0": (4.0, (("b_0", ""),)),
    "b_0": (0.9, (("c_0", ":K_0_0"),)),
    ":K_0_0": (10.0, (("c_0", ""),)),
    "c_0": (150.0, ()),
}
NEXT_LINKS = (("b_0", "", "", "", ":J_0_0"), ("c_0", "", "", "", ":K_0_0"))


def fake(vehicles: dict[str, tuple[str, float, float]]) -> Any:
    """A simulation with ``vehicles``: id -> (lane, front's position on it, length)."""

    def on(lane: str) -> list[str]:
        return [vid for vid, (at, _pos, _len) in vehicles.items() if at == lane]

    def links(lane: str) -> list[tuple[str, bool, bool, bool, str]]:
        return [(to, True, True, False, via) for to, via in LANES[lane][1]]

    lane = SimpleNamespace(
        getLength=lambda lane: LANES[lane][0], getLinks=links, getLastStepVehicleIDs=on
    )
    vehicle = SimpleNamespace(
        getLanePosition=lambda v: vehicles[v][1], getLength=lambda v: vehicles[v][2]
    )
    return SimpleNamespace(lane=lane, vehicle=vehicle)


def test_the_nearest_back_on_the_lanes_ahead_is_the_leader() -> None:
    # the ego's front at 90 m on a_0: a_0 ends 10 m on, :J_1_0 starts 18 m on, b_0 22 m on
    api = fake({"ego": ("a_0", 90.0, 5.0), "car": (":J_1_0", 3.0, 4.5),
                "far": ("c_0", 100.0, 5.0)})  # fmt: skip
    assert WayAhead({})(api, "a_0", 90.0, NEXT_LINKS) == (pytest.approx(16.5), "car")
    # with it gone, the one on c_0, which starts 10 + 12 + 0.9 + 10 = 32.9 m on
    api = fake({"ego": ("a_0", 90.0, 5.0), "far": ("c_0", 100.0, 5.0)})
    assert WayAhead({})(api, "a_0", 90.0, NEXT_LINKS) == (pytest.approx(127.9), "far")


def test_a_car_beside_or_behind_the_front_is_not_ahead_and_range_is_kept() -> None:
    # "side": its front level with the ego's; "back": behind it on the same lane
    api = fake({"side": ("a_0", 90.0, 4.0), "back": ("a_0", 60.0, 4.0),
                "away": ("c_0", 149.0, 5.0)})  # fmt: skip
    # away's back is 32.9 + 144 = 176.9 m on: in range; a range of 150 m leaves it out
    assert WayAhead({})(api, "a_0", 90.0, NEXT_LINKS) == (pytest.approx(176.9), "away")
    assert WayAhead({}, range_m=150.0)(api, "a_0", 90.0, NEXT_LINKS) is None
    # a leader known 170 m on: nothing nearer is ahead
    assert WayAhead({})(api, "a_0", 90.0, NEXT_LINKS, within_m=170.0) is None


def test_inside_a_junction_the_rest_of_its_link_comes_first() -> None:
    # the ego 2 m along :J_0_0 (6 m to its end); SUMO's next links then start after b_0
    api = fake({"car": ("b_0", 0.5, 4.0)})
    way = WayAhead({})
    assert [lane for lane, _start in way.lanes(api, ":J_0_0", 2.0, NEXT_LINKS[1:])] == [
        ":J_0_0",
        ":J_1_0",
        "b_0",
        ":K_0_0",
        "c_0",
    ]
    # its front 6 + 4 + 0.5 = 10.5 m on, its back 4 m behind that
    assert way(api, ":J_0_0", 2.0, NEXT_LINKS[1:]) == (pytest.approx(6.5), "car")


# a main road W -> M -> E with a short link road M -> N -> E: cars stand on the junctions'
# internal lanes and short edges the ego drives through
NODES = """<nodes>
  <node id="W" x="-200" y="0" type="priority"/>
  <node id="M" x="0" y="0" type="priority"/>
  <node id="N" x="2" y="0" type="priority"/>
  <node id="E" x="300" y="0" type="priority"/>
</nodes>"""
EDGES = """<edges>
  <edge id="WM" from="W" to="M" numLanes="1" speed="13.89"/>
  <edge id="MN" from="M" to="N" numLanes="1" speed="13.89"/>
  <edge id="NE" from="N" to="E" numLanes="1" speed="13.89"/>
</edges>"""


@pytest.fixture(scope="module")
def chain(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("chain")
    (folder / "empty.rou.xml").write_text(NO_DEMAND)
    return plain_net(folder, "chain", NODES, EDGES, "<connections/>"), folder / "empty.rou.xml"


@pytest.mark.slow
def test_on_a_real_network_the_reading_agrees_with_sumos_leader(
    make_env: Callable[..., UrbanDriveEnv], chain: tuple[Path, Path]
) -> None:
    net, demand = chain
    env = make_env(net_file=net, route=("WM", "NE"), demand_file=demand, warmup_s=0,
                   max_steps=60)  # fmt: skip
    obs, _info = env.reset(seed=0)
    api = env.sumo
    api.route.add("on", ["MN", "NE"])
    api.vehicle.add("car", "on", departPos="1.5", departSpeed="0")  # its back on N's lane
    api.vehicle.setSpeed("car", 0.0)
    way, seen = WayAhead({}), 0
    for _ in range(60):
        lane, pos = api.vehicle.getLaneID("ego"), api.vehicle.getLanePosition("ego")
        ours = way(api, lane, pos, api.vehicle.getNextLinks("ego"))
        sumo = api.vehicle.getLeader("ego", S.SENSOR_RANGE_M)
        if sumo and sumo[0]:
            seen += 1
            assert ours is not None and ours[1] == "car"
            assert ours[0] == pytest.approx(sumo[1] + api.vehicle.getMinGap("ego"), abs=1e-6)
            # the env's leader reads the same
            assert float(obs[S.D_LEAD]) == pytest.approx(ours[0], abs=1e-3)
        if ours is not None and ours[0] < 30.0:
            break
        # up to 10 m/s, then hold the speed
        action = IDLE_ACTION + 1 if float(obs[S.V_EGO]) < 10.0 else IDLE_ACTION
        obs, _r, terminated, truncated, _info = env.step(action)
        assert not (terminated or truncated)
    assert seen > 5
