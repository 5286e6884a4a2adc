"""The generalisation table's scenarios: held-out draws and the networks SUMO's tools build."""

from __future__ import annotations

from pathlib import Path

from explaindrive.evaluation import generalisation as gen
from explaindrive.evaluation.spec import parse_policy
from explaindrive.sim.network import route_edges
from explaindrive.sim.route import load_route_geometry


def test_the_groups_and_their_routes(tmp_path: Path) -> None:
    groups = gen.scenario_groups(tmp_path)
    assert list(groups) == ["held-out generated", "netgenerate grid", "netgenerate spider",
                            "netgenerate random", "netconvert town"]  # fmt: skip
    assert [c.name for c in groups["held-out generated"]][::19] == ["random-100", "random-119"]
    lights, unsignalised = {}, {}
    for network in gen.NETWORKS:
        net = gen.built_network(network, tmp_path)
        geometry = load_route_geometry(net, route_edges(net, *network.route))
        lights[network.name] = [light.tls_id for light in geometry.lights]
        unsignalised[network.name] = sum(not j.signalized for j in geometry.junctions)
    assert lights == {"grid": ["B1", "C1", "D1"], "spider": ["C1", "B1", "B3", "C3"],
                      "random": ["1383", "685", "173", "134", "4", "103"],
                      "town": []}  # fmt: skip
    # the real-junction networks: 7 of the random route's 13 junctions have no light, and
    # the town's one is the priority junction where Give Way Road meets Main Street
    assert unsignalised == {"grid": 0, "spider": 1, "random": 7, "town": 1}
    plans = gen.plan_generalisation({"krauss": parse_policy("krauss")}, groups)
    # 20 scenarios x seeds 0, 1 x level 1.0; one scenario each for the networks
    assert {k: len(p.episodes) for k, p in plans.items()} == {
        ("krauss", "held-out generated"): 40,
        ("krauss", "netgenerate grid"): 2,
        ("krauss", "netgenerate spider"): 2,
        ("krauss", "netgenerate random"): 2,
        ("krauss", "netconvert town"): 2,
    }


def test_the_table_counts_every_violation_kind_per_group() -> None:
    from explaindrive.env.metrics import EpisodeResult
    from explaindrive.evaluation.runner import EpisodeRecord
    from explaindrive.evaluation.spec import EpisodeSpec

    def record(
        seed: int, speed: float, speeding: int, arrived: bool, yields: int = 0
    ) -> EpisodeRecord:
        result = EpisodeResult(
            steps=100, mean_speed_mps=speed, avg_headway_s=None, avg_ttc_s=None,
            avg_jerk_mps3=0.0, collisions=0, red_light_runs=0, ped_violations=0,
            speeding_steps=speeding, stop_latencies=(), unfinished_stops=0,
            stop_bound_misses=0, distance_m=800.0,
            travel_time_s=100.0 if arrived else None, total_reward=0.0, yield_violations=yields,
        )  # fmt: skip
        spec = EpisodeSpec(parse_policy("krauss"), seed, 1.0, "fast", ())
        return EpisodeRecord(spec, result, (), (), ())

    table = gen.generalisation_section(
        {("krauss", "held-out generated"): [record(0, 8.0, 3, True, 1), record(1, 6.0, 2, False)]}
    )
    row = next(line for line in table.splitlines() if line.startswith("| krauss"))
    # mean speed weighted by steps: (8 + 6) / 2 = 7; one yield violation; speeding
    # 3 + 2 = 5; one of two arrived
    assert row == "| krauss | 7.000 | 0/2 | 0 | 0 | 1 | 5 | 1/2 |"
