"""The family's junction features, each drawn for about a third of the seeds: J2's left-turn
lane with its arrows, the ego's permissive left turn at J2, and J1's light joined with a
second junction K1; the networks netconvert builds of them, and SUMO's Krauss ego driving
them without a red light, a yield violation or a collision."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from explaindrive.env.right_of_way import link_yields
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.sim.route import RouteLight, load_route_geometry, read_net
from explaindrive.sim.scenario.directory import cached_scenario_dir, load_scenario_dir
from explaindrive.sim.scenario.files import ScenarioFiles
from explaindrive.sim.scenario.generator import random_params

# seeds of 0-49 with the features on: 1 has the turn lane (70 m) and K1 (35 m after J1),
# 5 the left turn alone, 21 K1 alone (30 m), 11 and 23 all three
TURN_LANE_SEED, LEFT_TURN_SEED, JOINED_SEED = 1, 5, 21
KRAUSS_SEEDS = (1, 5, 11, 21, 23)


def _scenario(seed: int, cache: Path) -> ScenarioFiles:
    return load_scenario_dir(
        cached_scenario_dir(random_params(seed), f"random-{seed}", cache, seed), cache
    )


def _phases(net_file: Path, tls_id: str) -> list[tuple[int, str]]:
    """(duration, state) of each phase of a light's programme in the network file."""
    block = re.search(rf'<tlLogic id="{tls_id}".*?</tlLogic>', net_file.read_text(), re.S)
    assert block is not None
    found = re.findall(r'<phase duration="(\d+)"\s*state="([^"]+)"', block.group(0))
    return [(int(d), state) for d, state in found]


def test_features_are_drawn_for_about_a_third_of_the_seeds() -> None:
    drawn = [random_params(seed) for seed in range(50)]
    assert sum(p.turn_lane_m is not None for p in drawn) == 18
    assert sum(p.left_turn for p in drawn) == 19
    assert sum(p.joined_junction_m is not None for p in drawn) == 16
    held_out = [random_params(seed) for seed in range(100, 120)]
    assert sum(p.turn_lane_m is not None for p in held_out) == 6
    assert sum(p.left_turn for p in held_out) == 5
    assert sum(p.joined_junction_m is not None for p in held_out) == 7


def test_the_turn_lane_carries_its_arrows(tmp_path: Path) -> None:
    params = random_params(TURN_LANE_SEED)
    assert (params.turn_lane_m, params.left_turn) == (70.0, False)
    files = _scenario(TURN_LANE_SEED, tmp_path)
    net = read_net(files.net_file)
    # T2 is 70 m before J2; T2_J2 has a sidewalk and two car lanes, its opposite one
    xs = {n.getID(): n.getCoord()[0] for n in net.getNodes()}
    assert xs["J2"] - xs["T2"] == pytest.approx(70.0)
    assert (net.getEdge("T2_J2").getLaneNumber(), net.getEdge("J2_T2").getLaneNumber()) == (3, 2)
    arrows: set[tuple[int, str, str]] = set()
    for to_edge, conns in net.getEdge("T2_J2").getOutgoing().items():
        arrows |= {(c.getFromLane().getIndex(), to_edge.getID(), c.getDirection()) for c in conns
                   if c.getFromLane().allows("passenger")}  # fmt: skip
    # the right lane (1) straight and right, the left lane (2) left only
    assert arrows == {(1, "J2_E0", "s"), (1, "J2_J2S", "r"), (2, "J2_J2N", "l")}
    into = net.getEdge("Z2_T2").getOutgoing()[net.getEdge("T2_J2")]
    assert sorted(c.getToLane().getIndex() for c in into) == [1, 2]  # one lane into both
    # the ego goes straight: J2's light is read on the right lane's link only
    geometry = load_route_geometry(files.net_file, files.route_edges)
    assert geometry.lights[-1].tls_id == "J2"
    assert geometry.lights[-1].lane_links == (("T2_J2_1", 10),)
    assert files.plan is not None
    left = [f for f in files.plan.flows if f.id == "j2_west_north"]
    assert [(f.nodes[-3:], f.veh_per_hour) for f in left] == [
        (("T2", "J2", "J2N"), params.demand.j2_left)
    ]


def test_pedestrians_at_j2_walk_on_the_short_edge_of_a_turn_lane(tmp_path: Path) -> None:
    params = random_params(47)  # the shortest turn lane: 40 m in a block of 60 m
    assert (params.turn_lane_m, params.zone_end_to_j2_m) == (40.0, 60.0)
    files = _scenario(47, tmp_path)
    # they walk along T2_J2 from 3/4 to half of 40 - 12 m (its stretch in T2 and J2)
    walks = [(f.from_edge, f.depart_pos_m, f.to_edge, f.arrival_pos_m)
             for f in files.pedestrian_flows if f.id.startswith("j2_")]  # fmt: skip
    assert walks == [("T2_J2", 21.0, "J2_T2", 14.0), ("J2_T2", 21.0, "T2_J2", 14.0)]
    assert read_net(files.net_file).getEdge("T2_J2").getLength() > 21.0


def test_the_left_turn_is_a_permissive_green(tmp_path: Path) -> None:
    params = random_params(LEFT_TURN_SEED)
    assert (params.left_turn, params.turn_lane_m) == (True, None)
    files = _scenario(LEFT_TURN_SEED, tmp_path)
    assert files.route_edges[-2:] == ("Z2_J2", "J2_J2N")
    net = read_net(files.net_file)

    def link(a: str, b: str) -> int:
        (conn,) = net.getEdge(a).getOutgoing()[net.getEdge(b)]
        return int(conn.getTLLinkIndex())

    ego, oncoming = link("Z2_J2", "J2_J2N"), link("E0_J2", "J2_Z2")
    assert (ego, oncoming) == (11, 4)  # J2's links as on the paper's road
    # the main road's green (45 s on this seed): the ego's left turn must yield ("g") to the
    # oncoming traffic, which goes straight on the same green ("G")
    duration, state = _phases(files.net_file, "J2")[0]
    assert params.j2.main_green_s == 45
    assert (duration, state[ego], state[oncoming]) == (45, "g", "G")
    assert link_yields(state[ego]) and not link_yields(state[oncoming])
    geometry = load_route_geometry(files.net_file, files.route_edges)
    assert geometry.lights[-1].lane_links == (("Z2_J2_1", 11),)
    # the route ends on J2's north arm: its 150 m less J2's half width (7.2 m)
    assert geometry.length_m - geometry.edge_start_m[-1] == pytest.approx(150.0 - 7.2, abs=0.1)


def test_j1_and_k1_run_on_one_programme(tmp_path: Path) -> None:
    params = random_params(JOINED_SEED)
    assert params.joined_junction_m == 30.0
    files = _scenario(JOINED_SEED, tmp_path)
    net = read_net(files.net_file)
    assert sorted(t.getID() for t in net.getTrafficLights()) == ["J1", "J2"]
    geometry = load_route_geometry(files.net_file, files.route_edges)
    # two stop lines of J1's light 30 m apart (both 7.2 m before their junction's centre),
    # each with its own link: J1's straight link 10, K1's 22 (after J1's 12)
    assert geometry.lights[:2] == (
        RouteLight("J1", params.approach_m - 7.2, (("W0_J1_1", 10),)),
        RouteLight("J1", params.approach_m + 30.0 - 7.2, (("J1_K1_1", 22),)),
    )
    # the programme keeps J1's two streams and timings: 47 s main green, yellow 4, all-red 1,
    # 38 s for the side roads of both junctions at once
    phases = _phases(files.net_file, "J1")
    assert [d for d, _ in phases] == [47, 4, 1, 38, 4, 1] == list(params.j1.durations(0))
    main, side = phases[0][1], phases[3][1]
    assert (main[10], main[22], side[10], side[22]) == ("G", "G", "r", "r")
    assert side == "GGgrrrGGgrrrGGgrrrGGgrrr"  # J1's and K1's side roads, each 6 links


@pytest.mark.slow  # SUMO episodes
def test_sumo_krauss_drives_the_junction_features_safely(
    make_env: Callable[..., UrbanDriveEnv], tmp_path: Path
) -> None:
    flagged, lanes_on_t2, joined_links = [], set(), set()
    for scenario_seed in KRAUSS_SEEDS:
        directory = cached_scenario_dir(random_params(scenario_seed), f"random-{scenario_seed}",
                                        tmp_path, scenario_seed)  # fmt: skip
        env = make_env(scenario=str(directory), ego_model="krauss", max_steps=600, warmup_s=100)
        for seed in (0, 1):
            env.reset(seed=seed)
            for _ in range(600):
                lane = env.sumo.vehicle.getLaneID("ego")
                if lane.startswith("T2_J2"):
                    lanes_on_t2.add((scenario_seed, lane))
                if lane == "W0_J1_1":
                    joined_links.add(tuple((t[0], t[1]) for t in env.sumo.vehicle.getNextTLS("ego")
                                           if t[0] == "J1"))  # fmt: skip
                _obs, _r, terminated, truncated, info = env.step(3)
                if info["red_light_run"] or info["yield_violation"] or info["collision"]:
                    flagged.append((scenario_seed, seed, info["time_s"], info["site"]))
                if terminated or truncated:
                    break
            assert info["arrived"], (scenario_seed, seed)
    assert flagged == []
    # on the turn lane, the ego keeps to the left lane where it turns left (11, 23), else right
    assert lanes_on_t2 == {(1, "T2_J2_1"), (11, "T2_J2_2"), (23, "T2_J2_2")}
    # before J1 it sees both stop lines of the joined light, each with its own link
    assert (("J1", 10), ("J1", 22)) in joined_links
