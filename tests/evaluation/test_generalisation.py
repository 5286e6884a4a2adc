"""The generalisation table's scenarios: held-out draws and netgenerate networks."""

from __future__ import annotations

from pathlib import Path

from explaindrive.evaluation import generalisation as gen
from explaindrive.evaluation.spec import parse_policy
from explaindrive.sim.network import route_edges
from explaindrive.sim.route import load_route_geometry


def test_the_groups_and_their_routes(tmp_path: Path) -> None:
    groups = gen.scenario_groups(tmp_path)
    assert list(groups) == ["held-out generated", "netgenerate grid", "netgenerate spider"]
    assert [c.name for c in groups["held-out generated"]][::19] == ["random-100", "random-119"]
    lights = {}
    for network in gen.NETWORKS:
        net = gen.netgen_network(network, tmp_path)
        geometry = load_route_geometry(net, route_edges(net, *network.route))
        lights[network.name] = [light.tls_id for light in geometry.lights]
    assert lights == {"grid": ["B1", "C1", "D1"], "spider": ["C1", "B1", "B3", "C3"]}
    plans = gen.plan_generalisation({"krauss": parse_policy("krauss")}, groups)
    # 20 scenarios x seeds 0, 1 x level 1.0; one scenario each for the networks
    assert {k: len(p.episodes) for k, p in plans.items()} == {
        ("krauss", "held-out generated"): 40,
        ("krauss", "netgenerate grid"): 2,
        ("krauss", "netgenerate spider"): 2,
    }
