"""Own networks: routes between two edges, their geometry, demand start, clear errors."""

from __future__ import annotations

import gzip
import itertools
from collections.abc import Callable
from pathlib import Path

import pytest

from explaindrive.sim.network import (
    NetworkError,
    demand_begin_s,
    own_network,
    parse_route,
    route_edges,
)
from explaindrive.sim.route import load_route_geometry
from explaindrive.sim.scenario.files import default_scenario, generated_trips
from tests.conftest import GRID_WITH_LIGHTS


def test_a_grid_route_passes_three_lights(netgen: Callable[..., Path]) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS)
    edges = route_edges(net, "A1B1", "D1E1")
    assert edges == ("A1B1", "B1C1", "C1D1", "D1E1")
    geometry = load_route_geometry(net, edges)
    assert [light.tls_id for light in geometry.lights] == ["B1", "C1", "D1"]
    # the stop lines lie 200 m apart, one block each
    gaps = [b.stop_line_m - a.stop_line_m for a, b in itertools.pairwise(geometry.lights)]
    assert gaps == pytest.approx([200.0, 200.0], abs=0.5)
    assert geometry.crossings == () and geometry.limit_at(0.0) == pytest.approx(13.89)


def test_a_route_without_lights_is_valid(netgen: Callable[..., Path]) -> None:
    net = netgen("spider", "--spider.arm-number", "5", "--spider.circle-number", "3")
    edges = route_edges(net, *_two_far_edges(net))
    geometry = load_route_geometry(net, edges)
    assert geometry.length_m > 0 and geometry.lights == ()


def test_a_random_network_with_guessed_lights(netgen: Callable[..., Path], tmp_path: Path) -> None:
    net = netgen("rand", "--rand.iterations", "40", "--tls.guess", "true")
    scenario = own_network(net, _two_far_edges(net), tmp_path)
    assert scenario.route_edges[0] != scenario.route_edges[-1]
    assert scenario.begin_s == 0.0 and scenario.trips  # trips generated per traffic level
    # 60 veh/h per km of lane at level 1.0: 90 at level 1.5, no scaling by SUMO
    assert scenario.routes_files(1.5)[1].name.endswith("_90.rou.xml")
    assert scenario.demand_args(1.5) == []


def _two_far_edges(net: Path) -> tuple[str, str]:
    """Two edges of the network far apart that cars may drive between."""
    import sumolib

    n = sumolib.net.readNet(str(net))
    edges = [e for e in n.getEdges() if e.allows("passenger")]
    first = edges[0]
    reach = n.getReachable(first, "passenger")
    x0, y0 = first.getFromNode().getCoord()

    def dist(e: sumolib.net.edge.Edge) -> float:
        x, y = e.getToNode().getCoord()
        return float((x - x0) ** 2 + (y - y0) ** 2)

    return first.getID(), max(reach, key=dist).getID()


def test_unusable_networks_and_routes_are_named(
    netgen: Callable[..., Path], tmp_path: Path
) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS)
    with pytest.raises(NetworkError, match="edge 'Z9' not found in"):
        route_edges(net, "A1B1", "Z9")
    paper = default_scenario().net_file
    # the paper's road ends in dead ends without turnarounds: no way back west
    with pytest.raises(NetworkError, match="no path for cars from edge 'J2_E0' to 'W0_J1'"):
        route_edges(paper, "J2_E0", "W0_J1")
    with pytest.raises(NetworkError, match="does not allow cars"):
        route_edges(paper, "PXS_PX", "J2_E0")
    nodes = tmp_path / "plain.nod.xml"
    nodes.write_text("<nodes/>")
    with pytest.raises(NetworkError, match=r"is not a SUMO network \(its root element is <nodes>"):
        route_edges(nodes, "a", "b")
    with pytest.raises(NetworkError, match="network file not found"):
        route_edges(tmp_path / "missing.net.xml", "a", "b")
    with pytest.raises(NetworkError, match="must look like FROM_EDGE,TO_EDGE"):
        parse_route("A1B1")


def test_the_demand_starts_at_its_first_departure(tmp_path: Path) -> None:
    demand = tmp_path / "morning.rou.xml"
    demand.write_text(
        '<routes><vehicle id="a" depart="25260"><route edges="x"/></vehicle>'
        '<flow id="f" begin="25200" end="26000" period="5"><route edges="x"/></flow>'
        '<vehicle id="b" depart="triggered"><route edges="x"/></vehicle></routes>'
    )
    assert demand_begin_s(demand) == 25200.0


def test_each_lane_that_leads_on_has_its_own_signal_link(netgen: Callable[..., Path]) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS, "--default.lanenumber", "2")
    edges = route_edges(net, "A0B0", "D3D4")
    assert edges == ("A0B0", "B0B1", "B1B2", "B2B3", "B3C3", "C3D3", "D3D4")
    lights = {light.tls_id: light for light in load_route_geometry(net, edges).lights}
    # straight on at B1 from both lanes; the right turn at B3 only from the right lane
    assert [lane for lane, _ in lights["B1"].lane_links] == ["B0B1_0", "B0B1_1"]
    assert [lane for lane, _ in lights["B3"].lane_links] == ["B2B3_0"]
    assert lights["B3"].link_of("B2B3_1") is None
    assert lights["B1"].link_of("B0B1_0") != lights["B1"].link_of("B0B1_1")


def test_guessed_crossings_are_read_along_the_route(netgen: Callable[..., Path]) -> None:
    options = ("--sidewalks.guess", "true", "--crossings.guess", "true")
    net = netgen("grid", *GRID_WITH_LIGHTS, *options)
    geometry = load_route_geometry(net, route_edges(net, "A1B1", "D1E1"))
    # at each of B1, C1, D1 one crossing over the arm the ego comes from, one over the arm
    # it leaves by; both signalised, both before the light's stop line
    assert [c.crossing_edge.split("_")[0] for c in geometry.crossings] == [
        ":B1", ":B1", ":C1", ":C1", ":D1", ":D1"
    ]  # fmt: skip
    assert all(c.signalized for c in geometry.crossings)
    stops = sorted({c.stop_line_m for c in geometry.crossings})
    assert stops == [light.stop_line_m for light in geometry.lights]


def test_trips_are_made_for_a_network_named_relative_to_the_working_directory(
    netgen: Callable[..., Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS)
    monkeypatch.chdir(net.parent)
    trips = generated_trips(Path(net.name), tmp_path / "cache")
    assert trips.is_file() and "<vehicle" in trips.read_text()


def test_a_demand_whose_vehicle_types_are_elsewhere_is_refused(tmp_path: Path) -> None:
    # a real scenario's routes name types its additional file defines: SUMO would stop at
    # the first vehicle, so the file is refused before it starts, naming what to do
    demand = tmp_path / "city.rou.xml"
    demand.write_text(
        '<routes><vType id="bus"/><vTypeDistribution id="mix"><vType id="m1"/>'
        "</vTypeDistribution>"
        '<vehicle id="a" depart="5" type="bus"><route edges="x"/></vehicle>'
        '<vehicle id="b" depart="6" type="mix"><route edges="x"/></vehicle>'
        '<vehicle id="c" depart="7" type="DEFAULT_VEHTYPE"><route edges="x"/></vehicle>'
        '<vehicle id="d" depart="8"><route edges="x"/></vehicle></routes>'
    )
    assert demand_begin_s(demand) == 5.0
    demand.write_text(
        '<routes><vehicle id="Costa_0" depart="0" type="private"><route edges="x"/></vehicle>'
        '<flow id="f" begin="0" end="9" period="3" type="taxi"><route edges="x"/></flow>'
        '<vehicle id="Costa_1" depart="1" type="private"><route edges="x"/></vehicle></routes>'
    )
    with pytest.raises(NetworkError) as err:
        demand_begin_s(demand)
    assert str(err.value) == (
        f"demand file {demand}: vehicle 'Costa_0' has type 'private', which the file does not "
        "define and 1 more undefined types; put the scenario's <vType> definitions (often in "
        "an .add.xml) into it"
    )


def test_a_compressed_network_and_demand_are_read_as_sumo_reads_them(
    netgen: Callable[..., Path], tmp_path: Path
) -> None:
    # real scenarios ship .net.xml.gz and .rou.xml.gz, which SUMO and sumolib read as they are
    net = tmp_path / "grid.net.xml.gz"
    net.write_bytes(gzip.compress(netgen("grid", *GRID_WITH_LIGHTS).read_bytes()))
    demand = tmp_path / "morning.rou.xml.gz"
    demand.write_bytes(
        gzip.compress(
            b'<routes><vType id="car"/>'
            b'<trip id="a" depart="25230" from="A1B1" to="D1E1" type="car"/></routes>'
        )
    )
    files = own_network(net, ("A1B1", "D1E1"), tmp_path / "cache", demand)
    assert files.route_edges == ("A1B1", "B1C1", "C1D1", "D1E1")
    assert (files.begin_s, files.demand_files) == (25230.0, (demand,))
    broken = tmp_path / "broken.net.xml.gz"
    broken.write_bytes(gzip.compress(b"<net><edge")[:-4])  # cut short
    with pytest.raises(NetworkError, match=r"broken\.net\.xml\.gz is not a SUMO network"):
        route_edges(broken, "A1B1", "D1E1")
