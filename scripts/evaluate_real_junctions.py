"""The passenger targets on real junctions: SUMO's Krauss and the networks, bare, on networks
with priority junctions, permissive turns, lane arrows and joined lights, each with the
trips ``randomTrips.py`` generates over it (the env's own demand for a network of your own).

* ``rand``: a ``netgenerate --rand`` network, priority junctions with lights where
  netconvert's heuristic puts them (``--tls.guess``), lights joined into clusters up to 40 m
  across, two lanes a way; two ego routes drawn with a fixed seed among the shortest paths
  that pass at least one priority junction and one light.
* ``town``: the small town ``tests/env/data/town.osm.xml``, built by netconvert as any
  OpenStreetMap extract; the ego turns from Give Way Road onto Main Street (a minor link)
  and drives on through the signal.

Each driver runs seeds 10-19 at traffic 1.0 and 1.5 (``explaindrive evaluate ... --no-shield``,
one process), and the table gives what the issue's targets read: episodes arrived,
collisions, red-light runs, pedestrian-yield and yield violations, speeding steps, the mean
speed (and its share of Krauss's on the same episodes) and hard brakes per episode::

    python scripts/evaluate_real_junctions.py [--fast POLICY] [--comfort POLICY] [--out DIR]
"""

from __future__ import annotations

import argparse
import itertools
import json
import random
import subprocess
import sys
from pathlib import Path

from explaindrive.sim.sumo_home import sumo_binary

ROOT = Path(__file__).resolve().parents[1]
TOWN_OSM = ROOT / "tests" / "env" / "data" / "town.osm.xml"
SEEDS, TRAFFIC = "10-19", "1.0,1.5"
RAND = ("--rand", "--rand.iterations", "80", "--seed", "5", "--default-junction-type",
        "priority", "--tls.guess", "true", "--tls.join", "true", "--tls.join-dist", "40",
        "--no-turnarounds", "true", "--default.lanenumber", "2", "--rand.min-distance", "60",
        "--rand.max-distance", "200")  # fmt: skip
TOWN_ROUTE = ("30#0", "10#2")  # Give Way Road onto Main Street, through the signal


def build(out: Path) -> dict[str, Path]:
    """The two networks, built into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    nets = {"rand": out / "rand.net.xml", "town": out / "town.net.xml"}
    subprocess.run([sumo_binary("netgenerate"), *RAND, "-o", str(nets["rand"])],
                   check=True, capture_output=True)  # fmt: skip
    subprocess.run([sumo_binary("netconvert"), "--osm-files", str(TOWN_OSM),
                    "--no-turnarounds", "true", "--geometry.remove", "true",
                    "-o", str(nets["town"])], check=True, capture_output=True)  # fmt: skip
    return nets


def rand_routes(net_file: Path, n: int = 2) -> list[tuple[str, str]]:
    """``n`` ego routes on the random network (drawn with seed 0): shortest paths of at
    least 6 edges and 600 m passing a priority junction and a light."""
    import sumolib

    net = sumolib.net.readNet(str(net_file))
    edges = sorted((e for e in net.getEdges() if e.allows("passenger")), key=lambda e: e.getID())
    rng, routes = random.Random(0), []
    for _ in range(20000):
        a, b = rng.sample(edges, 2)
        path, length = net.getShortestPath(a, b, vClass="passenger")
        if not path or len(path) < 6 or length < 600.0:
            continue
        kinds = {x.getToNode().getType() for x in path[:-1]}
        lights = any(c.getTLSID() for x, y in itertools.pairwise(path) for c in x.getConnections(y))
        if "priority" in kinds and lights:
            routes.append((a.getID(), b.getID()))
            if len(routes) == n:
                return routes
    raise SystemExit(f"no {n} routes with a priority junction and a light on {net_file}")


def evaluate(driver: str, net: Path, route: tuple[str, str], out: Path) -> dict:
    """``explaindrive evaluate`` of one driver on one route; its overall aggregates."""
    report = out / f"{driver.replace('/', '_')}-{net.stem}-{'_'.join(route)}.json"
    cli = str(Path(sys.executable).parent / "explaindrive")
    done = subprocess.run([cli, "evaluate", driver, "--net", str(net),
                    "--route", ",".join(route), "--seeds", SEEDS, "--traffic", TRAFFIC,
                    "--no-shield", "--workers", "1", "--json", str(report)],
                   capture_output=True, text=True, check=False)  # fmt: skip
    if done.returncode != 0:
        raise SystemExit(f"evaluate {driver} on {net.name} failed: {done.stderr.strip()}")
    return json.loads(report.read_text())["runs"][0]["aggregates"]["overall"]


def row(name: str, driver: str, a: dict, krauss: dict) -> str:
    share = a["mean_speed_mps"] / krauss["mean_speed_mps"]
    return (f"| {name} | {driver} | {a['arrived']}/{a['episodes']} | {a['collision_episodes']} | "
            f"{a['red_light_runs']} | {a['ped_violations']} | {a['yield_violations']} | "
            f"{a['speeding_steps']} | {a['mean_speed_mps']:.3f} ({share:.1%}) | "
            f"{a['hard_brakes_per_episode']:.2f} |")  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fast", default="fast", help="fast policy (default: the shipped)")
    ap.add_argument("--comfort", default="comfort", help="comfort policy (default: shipped)")
    ap.add_argument("--out", type=Path, default=Path("real-junctions"))
    args = ap.parse_args(argv)
    nets = build(args.out)
    cases = [("rand", r) for r in rand_routes(nets["rand"])] + [("town", TOWN_ROUTE)]
    print(
        "| network, route | driver | arrived | collisions | red-light runs | ped-yield "
        "| yield | speeding steps | mean speed m/s (of Krauss's) | hard brakes /episode |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, route in cases:
        where = f"{name} {route[0]} -> {route[1]}"
        krauss = evaluate("krauss", nets[name], route, args.out)
        print(row(where, "krauss", krauss, krauss), flush=True)
        for driver in (args.fast, args.comfort):
            print(
                row(where, driver, evaluate(driver, nets[name], route, args.out), krauss),
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
