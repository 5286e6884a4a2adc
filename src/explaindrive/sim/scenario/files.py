"""Files of a scenario: its network, the ego's route and the demand generated per traffic level.

A scenario is the paper's road, a road of the family (:mod:`explaindrive.sim.scenario.params`)
or a network of your own with a route through it (:mod:`explaindrive.sim.network`). The
first two carry their flows and pedestrians in a :class:`~explaindrive.sim.scenario.layout.
Layout`; an own network brings its background demand as route files, or has trips generated
over it for each traffic level (:func:`generated_trips`).
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from xml.sax.saxutils import quoteattr

from explaindrive.cache import cache_dir as user_cache_dir
from explaindrive.sim.scenario import layout
from explaindrive.sim.sumo_home import sumo_home

EGO_ROUTE_ID = "ego_route"
EGO_TYPE_ID = "ego_type"
EGO_ID = "ego"
# vTypes of the ego when SUMO drives it (baselines): same size and limits as the agent's ego.
BASELINE_EGO_TYPES: dict[str, str] = {"krauss": "ego_krauss", "idm": "ego_idm"}
FLOW_END_S = 4_000  # [s] flows outlast warm-up plus the longest episode
TRIPS_PER_HOUR_PER_KM = 60.0
"""[veh/h per km of lane] generated background trips at traffic level 1.0."""
TRIPS_SEED = 42
"""Seed of the generated trips (the episode seed varies the simulation itself)."""


class NetworkError(ValueError):
    """A network, route or demand file that cannot be used; the message names why."""


def package_data_dir() -> Path:
    """Directory of the committed scenario files inside the package."""
    return Path(str(resources.files("explaindrive.sim.scenario") / "data"))


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def routes_xml(
    traffic_level: float,
    plan: layout.Layout | None = layout.PAPER_LAYOUT,
    route_edges: tuple[str, ...] = layout.EGO_ROUTE_EDGES,
) -> str:
    """Vehicle demand at a traffic level: the vehicle types, the ego route and the plan's
    flows with Poisson arrivals (none without a plan).

    Flows scale with the level; level 1.0 puts 900 veh/h on the paper's main road.
    Pedestrians are added by :class:`explaindrive.sim.pedestrians.PedestrianSource`.
    """
    level = layout.validate_traffic_level(traffic_level)
    lines = ["<routes>"]
    lines.append(
        f'    <vType id="{EGO_TYPE_ID}" length="5" minGap="2.5" maxSpeed="20" accel="3" '
        'decel="3" emergencyDecel="9" color="1,0,0" guiShape="passenger"/>'
    )
    for model, type_id in BASELINE_EGO_TYPES.items():
        cf = "Krauss" if model == "krauss" else "IDM"
        lines.append(
            f'    <vType id="{type_id}" length="5" minGap="2.5" maxSpeed="20" accel="3" '
            f'decel="3" emergencyDecel="9" speedFactor="1" speedDev="0" '
            f'carFollowModel="{cf}" color="0,0,1"/>'
        )
    lines.append(
        '    <vType id="background" length="5" minGap="2.5" maxSpeed="20" accel="2.6" '
        'decel="4.5" sigma="0.5" carFollowModel="Krauss" color="0.8,0.8,0.2"/>'
    )
    lines.append(f'    <route id="{EGO_ROUTE_ID}" edges="{" ".join(route_edges)}"/>')
    for flow in plan.flows if plan is not None else ():
        if flow.veh_per_hour <= 0:
            continue
        rate = flow.veh_per_hour * level / 3600.0  # [veh/s]
        attrs = {
            "id": flow.id,
            "type": "background",
            "begin": "0",
            "end": str(FLOW_END_S),
            "period": f"exp({_fmt(rate)})",
            "departLane": "best",
            "departSpeed": "max",
            "departPos": "base",
        }
        attr_text = " ".join(f"{k}={quoteattr(v)}" for k, v in attrs.items())
        lines.append(f"    <flow {attr_text}>")
        lines.append(f'        <route edges="{" ".join(flow.edges)}"/>')
        lines.append("    </flow>")
    lines.append("</routes>")
    return "\n".join(lines) + "\n"


def generated_trips(net_file: Path, cache_dir: Path, traffic_level: float = 1.0) -> Path:
    """Background trips over the whole network at a traffic level, made once per network and
    level with ``randomTrips.py`` and cached.

    Raises:
        NetworkError: if randomTrips fails (e.g. no two edges are connected).
    """
    digest = hashlib.sha1(net_file.read_bytes()).hexdigest()[:10]
    density = TRIPS_PER_HOUR_PER_KM * traffic_level  # [veh/h per km of lane]
    path = cache_dir / "trips" / f"{digest}_{density:g}.rou.xml"
    if path.exists():
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=path.parent))
    script = sumo_home() / "tools" / "randomTrips.py"
    args = [
        sys.executable, str(script), "-n", str(net_file.resolve()), "-o", str(tmp / "trips.xml"),
        "-r", str(tmp / "routes.rou.xml"), "--begin", "0", "--end", str(FLOW_END_S),
        "--insertion-density", f"{density:g}", "--seed", str(TRIPS_SEED),
        "--vehicle-class", "passenger", "--fringe-factor", "5", "--min-distance", "100",
        "--prefix", "bg", "--validate",
        "--trip-attributes", 'departLane="best" departSpeed="max"',
    ]  # fmt: skip
    proc = subprocess.run(args, capture_output=True, text=True, check=False, cwd=tmp)
    routes = tmp / "routes.rou.xml"
    if proc.returncode != 0 or not routes.is_file():
        detail = (proc.stderr or proc.stdout).strip().splitlines()[-1:] or ["no output"]
        raise NetworkError(f"randomTrips.py could not make trips for {net_file}: {detail[0]}")
    os.replace(routes, path)
    for leftover in tmp.iterdir():
        leftover.unlink()
    tmp.rmdir()
    return path


@dataclass(frozen=True, slots=True)
class ScenarioFiles:
    """A scenario: its network, the ego's route, its demand, and where generated files go.

    Attributes:
        net_file: the SUMO network.
        cache_dir: where demand files and warm-up states are kept.
        route_edges: the ego's route.
        plan: the family layout whose flows and pedestrians are the demand; ``None`` for an
            own network, whose demand is ``demand_files``.
        demand_files: background demand of an own network; SUMO scales it by the traffic
            level (``--scale``).
        trips: whether an own network's demand is trips generated over it at the traffic
            level (:func:`generated_trips`).
        begin_s: simulation time at which the demand starts [s]; the warm-up runs from it.
        name: how tables and logs name the scenario.
    """

    net_file: Path
    cache_dir: Path
    route_edges: tuple[str, ...] = layout.EGO_ROUTE_EDGES
    plan: layout.Layout | None = layout.PAPER_LAYOUT
    demand_files: tuple[Path, ...] = ()
    trips: bool = False
    begin_s: float = 0.0
    name: str = "paper"

    @property
    def pedestrian_flows(self) -> tuple[layout.PedestrianFlow, ...]:
        """The pedestrians the environment adds (an own network's come with its demand)."""
        return self.plan.pedestrian_flows if self.plan is not None else ()

    @property
    def strategic_lane_changes(self) -> bool:
        """Whether SUMO changes the ego's lanes to follow its route (own networks, which
        may have several lanes). The family's roads have one lane but for J2's turn lane,
        which starts at a node whose one lane leads into both: SUMO takes the ego into the
        one its route needs there, without a lane change."""
        return self.plan is None

    def routes_files(self, traffic_level: float) -> tuple[Path, ...]:
        """The route files SUMO loads at a traffic level: the generated one first."""
        if self.trips:
            return (self.routes_file(traffic_level),
                    generated_trips(self.net_file, self.cache_dir, traffic_level))  # fmt: skip
        return (self.routes_file(traffic_level), *self.demand_files)

    def demand_args(self, traffic_level: float) -> list[str]:
        """SUMO options for the demand at a traffic level, besides its route files."""
        args = ["--begin", f"{self.begin_s:g}"] if self.begin_s else []
        if self.demand_files:
            args += ["--scale", f"{traffic_level:g}"]
        return args

    def state_reloads(self, traffic_level: float) -> bool:
        """Whether a saved warm-up state reloads: not for a demand file scaled above 1, whose
        copied vehicles SUMO 1.28 cannot restore (their routes are unknown on loading)."""
        return not (self.demand_files and traffic_level > 1.0)

    def demand_key(self, traffic_level: float) -> str:
        """Names the demand at a traffic level (level and content hash) in cached files."""
        key = self.routes_file(traffic_level).name.removesuffix(".rou.xml")
        args = self.demand_args(traffic_level)
        if not self.demand_files and not self.trips and not args:
            return key
        files = self.routes_files(traffic_level)[1:]
        extra = "|".join([*(_digest(p) for p in files), *args])
        return f"{key}_{hashlib.sha1(extra.encode()).hexdigest()[:10]}"

    def check(self) -> None:
        """Raise ``FileNotFoundError`` with a clear message if the network is missing."""
        if not self.net_file.is_file():
            raise FileNotFoundError(
                f"SUMO network file not found: {self.net_file} "
                "(rebuild it with `explaindrive scenario build`)"
            )

    @property
    def net_digest(self) -> str:
        """Short content hash of the network, used to key cached files."""
        digest = hashlib.sha1(self.net_file.read_bytes()).hexdigest()
        return digest[:10]

    def routes_file(self, traffic_level: float) -> Path:
        """Demand file for a traffic level, written on first use (atomically)."""
        text = routes_xml(traffic_level, self.plan, self.route_edges)
        key = hashlib.sha1(text.encode()).hexdigest()[:10]
        path = self.cache_dir / "routes" / f"level{traffic_level:g}_{key}.rou.xml"
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
            with os.fdopen(fd, "w") as fh:
                fh.write(text)
            os.replace(tmp, path)
        return path

    def state_dir(self) -> Path:
        """Directory of cached warm-up states."""
        return self.cache_dir / "states" / self.net_digest


def _digest(path: Path) -> str:
    return hashlib.sha1(path.read_bytes()).hexdigest()[:10]


def default_scenario(cache_dir: Path | None = None) -> ScenarioFiles:
    """The shipped urban scenario."""
    return ScenarioFiles(
        net_file=package_data_dir() / "urban.net.xml",
        cache_dir=cache_dir or user_cache_dir(),
    )
