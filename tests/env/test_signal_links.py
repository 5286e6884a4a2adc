"""Signals read per lane and per link: the stop line and signal index of the link the ego
will use, on joined clusters (one programme for several junctions) too; and SUMO's own
Krauss driver, whose safety checks are on, runs no red light, crosses no yield line in front
of a foe with priority and collides with nothing on any network of the tests (a network
built from OpenStreetMap among them)."""

from __future__ import annotations

import itertools
import random
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest

from explaindrive.env import state as S
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.evaluation.generalisation import NETWORKS, built_network
from explaindrive.sim.route import RouteJunction
from explaindrive.sim.sumo_home import sumo_binary
from tests.conftest import GRID_WITH_LIGHTS, plain_net

pytestmark = pytest.mark.slow  # SUMO episodes


# A road from W to E crosses a dual carriageway: a northbound one-way road at J1 and a
# southbound one at J2, 40 m apart. One programme, "C", runs both junctions (a joined
# cluster: two stop lines on the route). WJ1's left lane turns left only (its arrow), so the
# ego keeps to the right lane, and J1 and J2 are both passed on the way to E.
NODES = """<nodes>
  <node id="W" x="-300" y="0" type="priority"/>
  <node id="J1" x="0" y="0" type="traffic_light" tl="C"/>
  <node id="J2" x="40" y="0" type="traffic_light" tl="C"/>
  <node id="E" x="340" y="0" type="priority"/>
  <node id="S1" x="0" y="-300" type="priority"/>
  <node id="N1" x="0" y="300" type="priority"/>
  <node id="N2" x="40" y="300" type="priority"/>
  <node id="S2" x="40" y="-300" type="priority"/>
</nodes>"""
EDGES = """<edges>
  <edge id="WJ1" from="W" to="J1" numLanes="2" speed="13.89"/>
  <edge id="J1J2" from="J1" to="J2" numLanes="2" speed="13.89"/>
  <edge id="J2E" from="J2" to="E" numLanes="2" speed="13.89"/>
  <edge id="EJ2" from="E" to="J2" numLanes="2" speed="13.89"/>
  <edge id="J2J1" from="J2" to="J1" numLanes="2" speed="13.89"/>
  <edge id="J1W" from="J1" to="W" numLanes="2" speed="13.89"/>
  <edge id="S1J1" from="S1" to="J1" numLanes="1" speed="13.89"/>
  <edge id="J1N1" from="J1" to="N1" numLanes="1" speed="13.89"/>
  <edge id="N2J2" from="N2" to="J2" numLanes="1" speed="13.89"/>
  <edge id="J2S2" from="J2" to="S2" numLanes="1" speed="13.89"/>
</edges>"""
CONNECTIONS = """<connections>
  <connection from="WJ1" to="J1J2" fromLane="0" toLane="0"/>
  <connection from="WJ1" to="J1J2" fromLane="0" toLane="1"/>
  <connection from="WJ1" to="J1N1" fromLane="1" toLane="0"/>
</connections>"""
# netconvert's lengths: WJ1 296.0 m, J1's internal lane 11.5 m, J1J2 25.6 m
J1_LINE_M = 296.0  # [m] J1's stop line from the start of WJ1
J2_LINE_M = 296.0 + 11.5 + 25.6  # [m] J2's: 333.1
# the programme's link indices: WJ1_0 -> J1J2_0 | J1J2_1 and on, J1J2_0 | _1 -> J2E
LINKS = {"J1J2_0": (6, 16), "J1J2_1": (7, 17)}


@pytest.fixture(scope="module")
def dual_carriageway(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The joined cluster above, built by netconvert from plain XML."""
    return plain_net(tmp_path_factory.mktemp("dual"), "dual", NODES, EDGES, CONNECTIONS)


@pytest.fixture(scope="module")
def random_joined(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A netgenerate random network, its lights joined into clusters up to 40 m across."""
    out = tmp_path_factory.mktemp("rand") / "rand.net.xml"
    subprocess.run([sumo_binary("netgenerate"), "--rand", "--rand.iterations", "60",
                    "--seed", "3", "--default-junction-type", "traffic_light",
                    "--tls.join", "true", "--tls.join-dist", "40", "--no-turnarounds", "true",
                    "--default.lanenumber", "2", "--rand.min-distance", "30",
                    "--rand.max-distance", "150", "-o", str(out)],
                   check=True, capture_output=True)  # fmt: skip
    return out


@pytest.fixture(scope="module")
def osm_town(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small town written as OpenStreetMap (``sim/scenario/data/town.osm.xml``): Main
    Street (primary, 50 km/h) crosses Signal Lane at a traffic signal and Give Way Road
    (residential, 30 km/h) at a priority junction, built by netconvert as any OSM extract
    (as the generalisation table builds it)."""
    town = next(n for n in NETWORKS if n.name == "town")
    return built_network(town, tmp_path_factory.mktemp("osm"))


def joined_routes(net_file: Path, n: int) -> list[tuple[str, str]]:
    """``n`` routes (drawn with a fixed seed) whose shortest paths pass a joined cluster."""
    import sumolib

    net = sumolib.net.readNet(str(net_file))
    edges = [e for e in net.getEdges() if e.allows("passenger")]
    rng, routes = random.Random(0), []
    while len(routes) < n:
        a, b = rng.sample(edges, 2)
        path, _ = net.getShortestPath(a, b, vClass="passenger")
        if not path or len(path) < 4:
            continue
        tls = {c.getTLSID() for x, y in itertools.pairwise(path) for c in x.getConnections(y)}
        if any(t.startswith("joined") for t in tls):
            routes.append((a.getID(), b.getID()))
    return routes


def test_each_stop_line_of_a_joined_cluster_is_read_with_its_own_link(
    make_env: Callable[..., UrbanDriveEnv], dual_carriageway: Path
) -> None:
    env = make_env(net_file=dual_carriageway, route=("WJ1", "J2E"), ego_model="krauss",
                   max_steps=200, warmup_s=60)  # fmt: skip
    # both junctions' areas run from their stop lines over internal lanes of 11.5 m and 11.2 m
    assert env.geometry.junctions == (
        RouteJunction("J1", J1_LINE_M, J1_LINE_M + 11.5, signalized=True, crossing=False),
        RouteJunction("J2", J2_LINE_M, J2_LINE_M + 11.2, signalized=True, crossing=False),
    )
    obs, _ = env.reset(seed=0)
    api = env.sumo
    assert api.vehicle.getLaneID("ego") == "WJ1_0"  # the left lane only turns left
    seen = env._episode().seen
    assert seen is not None
    (tls1, link1, gap1, _), (tls2, link2, gap2, _) = seen.links
    start = api.vehicle.getLanePosition("ego")
    assert (tls1, tls2) == ("C", "C")  # one programme, two stop lines
    assert (link1, link2) in LINKS.values()  # each its own link, on one lane of J1J2
    assert gap1 == pytest.approx(J1_LINE_M - start, abs=1e-6)
    assert gap2 - gap1 == pytest.approx(J2_LINE_M - J1_LINE_M, abs=1e-6)  # 37.1 m
    assert obs[S.D_TL] == S.SENSOR_RANGE_M  # J1 is beyond the 200 m of the sensor
    on_j1j2 = False
    for _ in range(200):
        seen = env._episode().seen
        assert seen is not None
        if seen.links and seen.links[0].gap_m < S.SENSOR_RANGE_M:
            # the light shown is the link's own signal, read from the programme's state
            link = seen.links[0]
            state = api.trafficlight.getRedYellowGreenState("C")[link.link_index]
            assert obs[S.TLS] == float(S.LightState.from_sumo(state))
        lane = api.vehicle.getLaneID("ego")
        if lane in LINKS:  # between the two stop lines: J2's link of this lane is next
            on_j1j2 = True
            assert [link.link_index for link in seen.links] == [LINKS[lane][1]]
        elif lane == "WJ1_0":  # before J1: its link, then J2's on the same lane of J1J2
            assert tuple(link.link_index for link in seen.links) in LINKS.values()
        obs, _r, terminated, truncated, info = env.step(3)
        assert not info["red_light_run"]
        if terminated or truncated:
            break
    assert on_j1j2 and info["arrived"]


def network_cases(
    dual: Path, rand: Path, town: Path, netgen: Callable[..., Path]
) -> list[dict[str, object]]:
    """Env configs of every network of the tests, with routes through their lights."""
    two_lane = netgen("grid", *GRID_WITH_LIGHTS, "--default.lanenumber", "2")
    spider = netgen("spider", "--spider.arm-number", "5", "--spider.circle-number", "3",
                    "--spider.space-radius", "150",
                    "--default-junction-type", "traffic_light")  # fmt: skip
    cases: list[dict[str, object]] = [
        {},  # the paper's road
        {"scenario": "random", "scenario_every": 1},  # the generated family
        {"net_file": netgen("grid", *GRID_WITH_LIGHTS), "route": ("A1B1", "D1E1")},
        {"net_file": two_lane, "route": ("A0B0", "D3D4")},
        {"net_file": spider, "route": ("D1C1", "C3D3")},
        {"net_file": dual, "route": ("WJ1", "J2E")},
        # Main Street through the signal and over the priority junction (the major road)
        {"net_file": town, "route": ("10#0", "10#2")},
        # Give Way Road turning onto Main Street: a minor link, the ego must yield
        {"net_file": town, "route": ("30#0", "10#2")},
    ]
    cases += [{"net_file": rand, "route": route} for route in joined_routes(rand, 4)]
    return cases


def test_sumo_krauss_runs_no_red_light_and_yields_on_any_network_of_the_tests(
    make_env: Callable[..., UrbanDriveEnv],
    netgen: Callable[..., Path],
    dual_carriageway: Path,
    random_joined: Path,
    osm_town: Path,
) -> None:
    flagged, episodes = [], 0
    for case in network_cases(dual_carriageway, random_joined, osm_town, netgen):
        env = make_env(ego_model="krauss", max_steps=400, warmup_s=100, **case)
        for seed in (0, 1):
            env.reset(seed=seed)
            episodes += 1
            for _ in range(400):
                _obs, _r, terminated, truncated, info = env.step(3)
                if info["red_light_run"] or info["yield_violation"] or info["collision"]:
                    flagged.append((env.scenario.name, seed, info["time_s"], info["site"]))
                if terminated or truncated:
                    break
    assert episodes == 24
    assert flagged == []
