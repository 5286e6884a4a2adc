"""The passenger targets on real junctions: SUMO's Krauss and the networks, bare, on the
generalisation table's networks with priority junctions and minor links
(``explaindrive.evaluation.generalisation.REAL_JUNCTIONS``), each with the trips
``randomTrips.py`` generates over it (the env's own demand for a network of your own).

* ``random``: a ``netgenerate --rand`` network with random road priorities and lights where
  netconvert's heuristic puts them; the ego's route passes 13 junctions, 7 without a light.
* ``town``: the small town ``sim/scenario/data/town.osm.xml``, built by netconvert as any
  OpenStreetMap extract; the ego turns from Give Way Road onto Main Street (a minor link).

``--city NAME NET FROM,TO DEMAND`` (repeatable) adds a network of your own with its own
demand, a real city's say; ``--only-cities`` leaves out the two networks above.

Each driver runs seeds 10-19 at traffic 1.0 and 1.5 (``explaindrive evaluate ... --no-shield``,
one process), and the table gives what the passenger targets read: episodes arrived,
collisions, red-light runs, pedestrian-yield and yield violations, speeding steps, the mean
speed (and its share of Krauss's on the same episodes) and hard brakes per episode::

    python scripts/evaluate_real_junctions.py [--fast POLICY] [--comfort POLICY] [--out DIR]
        [--city NAME NET FROM,TO DEMAND ...] [--only-cities]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from explaindrive.evaluation.generalisation import NETWORKS, REAL_JUNCTIONS, built_network

SEEDS, TRAFFIC = "10-19", "1.0,1.5"


@dataclass(frozen=True)
class Case:
    """One network and route the drivers are compared on."""

    name: str
    net: Path
    route: tuple[str, str]
    demand: Path | None = None  # None: the trips the env generates over the network


def city(values: list[str]) -> Case:
    """A ``--city NAME NET FROM,TO DEMAND`` case; exits with one line if it cannot be used."""
    name, net, route, demand = values
    ends = tuple(route.split(","))
    if len(ends) != 2 or not all(ends):
        raise SystemExit(f"--city {name}: route {route!r} is not FROM,TO")
    for path in (Path(net), Path(demand)):
        if not path.is_file():
            raise SystemExit(f"--city {name}: no such file {path}")
    return Case(name, Path(net), (ends[0], ends[1]), Path(demand))


def evaluate(driver: str, case: Case, out: Path) -> dict:
    """``explaindrive evaluate`` of one driver on one case; its overall aggregates."""
    net, route = case.net, case.route
    stem = "_".join(route).replace("[", "(").replace("]", ")")
    report = out / f"{driver.replace('/', '_')}-{net.stem}-{stem}.json"
    cli = str(Path(sys.executable).parent / "explaindrive")
    demand = ["--demand", str(case.demand)] if case.demand else []
    done = subprocess.run([cli, "evaluate", driver, "--net", str(net),
                    "--route", ",".join(route), *demand, "--seeds", SEEDS, "--traffic", TRAFFIC,
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
    ap.add_argument("--city", nargs=4, action="append", default=[],
                    metavar=("NAME", "NET", "FROM,TO", "DEMAND"),
                    help="a network of your own with its demand (repeatable)")  # fmt: skip
    ap.add_argument("--only-cities", action="store_true", help="only the --city networks")
    args = ap.parse_args(argv)
    cities = [city(values) for values in args.city]
    if args.only_cities and not cities:
        raise SystemExit("--only-cities needs at least one --city")
    args.out.mkdir(parents=True, exist_ok=True)
    cases = [] if args.only_cities else [
        Case(n.name, built_network(n, args.out), n.route)
        for n in NETWORKS if n.name in REAL_JUNCTIONS
    ]  # fmt: skip
    print(
        "| network, route | driver | arrived | collisions | red-light runs | ped-yield "
        "| yield | speeding steps | mean speed m/s (of Krauss's) | hard brakes /episode |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for case in [*cases, *cities]:
        where = f"{case.name} {case.route[0]} -> {case.route[1]}"
        krauss = evaluate("krauss", case, args.out)
        print(row(where, "krauss", krauss, krauss), flush=True)
        for driver in (args.fast, args.comfort):
            print(row(where, driver, evaluate(driver, case, args.out), krauss), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
