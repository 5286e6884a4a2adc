"""The generalisation table of the results document: the policies off the road they were
trained on.

Five groups of scenarios: the 20 generated scenarios held out from training
(``random:100-119``); two networks SUMO's ``netgenerate`` makes with every junction signalised
(a grid and a spider web), each with a route through at least three lights; and two with
real junctions: a ``netgenerate`` random network with priority junctions (random road
priorities, lights where netconvert's heuristic puts them) and a small town netconvert builds
from OpenStreetMap (``sim/scenario/data/town.osm.xml``), where the ego turns from a minor road
onto the main street. Each has trips generated over the network. One row per policy; per
group the mean speed and the safety counts over every episode.
"""

from __future__ import annotations

import subprocess
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from explaindrive.evaluation.aggregate import summarize
from explaindrive.evaluation.runner import EpisodeRecord, Progress, run_grid
from explaindrive.evaluation.scenarios import (
    ScenarioCase,
    network_case,
    over_scenarios,
    parse_scenarios,
)
from explaindrive.evaluation.spec import PolicySpec, RunPlan, plan_run
from explaindrive.evaluation.tables import fmt
from explaindrive.sim.scenario.files import package_data_dir
from explaindrive.sim.sumo_home import sumo_binary

HELD_OUT = "random:100-119"
"""The held-out generated scenarios of the table."""
DEFAULT_SEEDS: tuple[int, ...] = (0, 1)
DEFAULT_LEVELS: tuple[float, ...] = (1.0,)


TOWN_OSM = "town.osm.xml"
"""A small town written as OpenStreetMap (``sim/scenario/data``): Main Street (primary,
50 km/h) crosses Signal Lane at a traffic signal and Give Way Road (residential, 30 km/h) at a
priority junction."""


@dataclass(frozen=True, slots=True)
class BuiltNetwork:
    """A network SUMO's tools build and the ego's route through it: ``netgenerate`` with
    ``options``, or, with ``osm``, ``netconvert`` from that shipped OpenStreetMap file."""

    name: str
    options: tuple[str, ...]
    route: tuple[str, str]
    osm: str = ""


NETWORKS: tuple[BuiltNetwork, ...] = (
    # 5 x 5 blocks of 200 m; A1B1 -> D1E1 passes the lights B1, C1, D1
    BuiltNetwork("grid", ("--grid", "--grid.number", "5", "--grid.length", "200",
                          "--default-junction-type", "traffic_light"), ("A1B1", "D1E1")),
    # 5 arms, 3 rings 150 m apart; D1C1 -> C3D3 crosses the centre: lights C1, B1, B3, C3
    BuiltNetwork("spider", ("--spider", "--spider.arm-number", "5", "--spider.circle-number",
                            "3", "--spider.space-radius", "150", "--default-junction-type",
                            "traffic_light"), ("D1C1", "C3D3")),
    # 80 random nodes, two lanes a way, random road priorities, lights where the sum of the
    # speeds in exceeds 90 km/h (36 priority junctions, 22 lights); 1039 -> -11 is 1,537 m
    # over 13 junctions, 7 of them priority junctions
    BuiltNetwork("random", ("--rand", "--rand.iterations", "80", "--rand.min-distance", "60",
                            "--rand.max-distance", "200", "--rand.random-priority", "true",
                            "--default.lanenumber", "2", "--default-junction-type", "priority",
                            "--tls.guess", "true", "--tls.guess.threshold", "90",
                            "--tls.join", "true", "--tls.join-dist", "40"), ("1039", "-11")),
    # from Give Way Road onto Main Street: a minor link at a priority junction
    BuiltNetwork("town", ("--geometry.remove", "true"), ("30#0", "10#2"), osm=TOWN_OSM),
)  # fmt: skip
REAL_JUNCTIONS = ("random", "town")
"""The networks with priority junctions and minor links."""


def built_network(network: BuiltNetwork, cache_dir: Path) -> Path:
    """The network file, built on first use and cached.

    Raises:
        RuntimeError: if netgenerate or netconvert fails.
    """
    out = cache_dir / "netgenerate" / f"{network.name}.net.xml"
    if not out.is_file():
        out.parent.mkdir(parents=True, exist_ok=True)
        if network.osm:
            tool = [sumo_binary("netconvert"), "--osm-files", str(package_data_dir() / network.osm)]
        else:
            tool = [sumo_binary("netgenerate"), "--seed", "7"]
        args = [*tool, *network.options, "--no-turnarounds", "true", "-o", str(out)]
        proc = subprocess.run(args, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise RuntimeError(f"{tool[0]} failed for {network.name}: {proc.stderr[-500:]}")
    return out


def scenario_groups(cache_dir: Path) -> dict[str, list[ScenarioCase]]:
    """The table's column groups: the held-out generated scenarios and each network."""
    groups: dict[str, list[ScenarioCase]] = {
        "held-out generated": list(parse_scenarios(HELD_OUT, cache_dir))
    }
    for network in NETWORKS:
        net = built_network(network, cache_dir)
        groups[f"{'netconvert' if network.osm else 'netgenerate'} {network.name}"] = [
            network_case(network.name, {"net_file": net, "route": network.route})
        ]
    return groups


def plan_generalisation(
    policies: Mapping[str, PolicySpec],
    groups: Mapping[str, Sequence[ScenarioCase]],
    seeds: Sequence[int] = DEFAULT_SEEDS,
    levels: Sequence[float] = DEFAULT_LEVELS,
    max_steps: int = 1000,
) -> dict[tuple[str, str], RunPlan]:
    """One run per (policy, group), each policy under its own command (merged excluded)."""
    return {
        (name, group): over_scenarios(plan_run(spec, seeds, levels, max_steps=max_steps), cases)
        for name, spec in policies.items()
        if spec.kind != "merged"
        for group, cases in groups.items()
    }


def run_generalisation(
    plans: Mapping[tuple[str, str], RunPlan],
    *,
    workers: int | None = None,
    use_ray: bool = False,
    ray_address: str | None = None,
    progress: Progress | None = None,
) -> str:
    """Evaluate the runs in one grid and return the section's Markdown."""
    specs = [ep for plan in plans.values() for ep in plan.episodes]
    records = run_grid(specs, workers=workers, use_ray=use_ray, ray_address=ray_address,
                       progress=progress)  # fmt: skip
    by_run: dict[tuple[str, str], list[EpisodeRecord]] = {}
    i = 0
    for key, plan in plans.items():
        by_run[key] = records[i : i + len(plan.episodes)]
        i += len(plan.episodes)
    return generalisation_section(by_run)


def generalisation_section(by_run: Mapping[tuple[str, str], Sequence[EpisodeRecord]]) -> str:
    """The table: a row per policy; per scenario group mean speed, collisions, red-light
    runs, pedestrian-yield violations, yield violations, speeding steps and arrivals over its
    episodes."""
    policies = list(dict.fromkeys(name for name, _ in by_run))
    groups = list(dict.fromkeys(group for _, group in by_run))
    header = ["policy"]
    for group in groups:
        header += [f"{group}: speed m/s", "collisions", "red runs", "ped viol.", "yield viol.",
                   "speeding", "arrived"]  # fmt: skip
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    for name in policies:
        row = [name]
        for group in groups:
            recs = by_run.get((name, group), [])
            o = summarize(name, [(r.spec.traffic_level, r.result) for r in recs]).overall
            row += [fmt(o.mean_speed_mps), f"{o.collision_episodes}/{o.episodes}",
                    str(o.red_light_runs), str(o.ped_violations), str(o.yield_violations),
                    str(o.speeding_steps),
                    f"{o.arrived}/{o.episodes}"]  # fmt: skip
        lines.append("| " + " | ".join(row) + " |")
    first = next(iter(by_run.values()), [])
    seeds = sorted({r.spec.seed for r in first})
    levels = sorted({r.spec.traffic_level for r in first})
    intro = (
        "\n## Generalisation\n\n"
        f"Roads no policy was trained on: the 20 generated scenarios held out from training "
        f"(`{HELD_OUT}`), two `netgenerate` networks with every junction signalised (a grid "
        "and a spider web), and two with priority junctions and minor links (a `netgenerate` "
        "random network with random road priorities, and a town netconvert builds from "
        "OpenStreetMap), with trips generated over them; seeds "
        f"{', '.join(map(str, seeds))}, traffic level(s) {', '.join(f'{x:g}' for x in levels)}."
        "\n\n"
    )
    return intro + "\n".join(lines) + "\n"
