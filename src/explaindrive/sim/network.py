"""A SUMO network of your own as a scenario: a route through it and its background demand.

The ego's route is SUMO's shortest path for passenger cars between two edges (sumolib);
its stop lines, crossings and speed limits are then read along that route
(:mod:`explaindrive.sim.route`). The background demand is a route file of your own,
starting wherever its first departure is (e.g. 25200 s, 7:00), which the traffic level
scales (SUMO's ``--scale``; 1.0 is the file as given), or else trips that SUMO's
``randomTrips.py`` generates over the whole network,
:data:`~explaindrive.sim.scenario.files.TRIPS_PER_HOUR_PER_KM` times the traffic level
(:func:`~explaindrive.sim.scenario.files.generated_trips`, which the scenario's files call
for each level).
"""

from __future__ import annotations

import gzip
import io
import logging
import xml.etree.ElementTree as ET
from pathlib import Path

from explaindrive.sim.scenario.files import NetworkError, ScenarioFiles, generated_trips

log = logging.getLogger(__name__)

XmlStream = gzip.GzipFile | io.BufferedReader
"""A network or route file opened for reading (:func:`open_xml`)."""

_DEPART_TAGS = ("vehicle", "trip", "flow", "person", "personFlow")
_TYPE_TAGS = ("vType", "vTypeDistribution")
SUMO_DEFAULT_TYPES = (
    "DEFAULT_VEHTYPE", "DEFAULT_PEDTYPE", "DEFAULT_BIKETYPE", "DEFAULT_CONTAINERTYPE",
    "DEFAULT_TAXITYPE", "DEFAULT_RAILTYPE",
)  # fmt: skip
"""The vehicle types SUMO defines itself: a demand file may use them without defining them."""


def open_xml(path: Path) -> XmlStream:
    """``path`` opened for reading, gzip-compressed or not (SUMO reads both, and real
    scenarios often ship ``.net.xml.gz`` and ``.rou.xml.gz``)."""
    with path.open("rb") as head:
        compressed = head.read(2) == b"\x1f\x8b"
    return gzip.GzipFile(path, "rb") if compressed else path.open("rb")


def check_network_file(net_file: Path) -> None:
    """Raise :class:`NetworkError` unless ``net_file`` is a SUMO network file."""
    if not net_file.is_file():
        raise NetworkError(f"network file not found: {net_file}")
    try:
        with open_xml(net_file) as stream:
            root = next(ET.iterparse(stream, events=("start",)))[1]
    except (ET.ParseError, OSError, EOFError) as exc:
        raise NetworkError(f"{net_file} is not a SUMO network (not XML: {exc})") from None
    if root.tag != "net":
        raise NetworkError(
            f"{net_file} is not a SUMO network (its root element is <{root.tag}>, not <net>)"
        )


def parse_route(text: str) -> tuple[str, str]:
    """``FROM_EDGE,TO_EDGE`` as a pair of edge ids.

    Raises:
        NetworkError: unless the text holds exactly two non-empty edge ids.
    """
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 2 or not all(parts):
        raise NetworkError(f"route {text!r} must look like FROM_EDGE,TO_EDGE")
    return parts[0], parts[1]


def route_edges(net_file: Path, from_edge: str, to_edge: str) -> tuple[str, ...]:
    """SUMO's shortest route for passenger cars from ``from_edge`` to ``to_edge``.

    Raises:
        NetworkError: if an edge is missing, does not allow cars, or no path joins them.
    """
    import sumolib

    check_network_file(net_file)
    net = sumolib.net.readNet(str(net_file))
    for edge_id in (from_edge, to_edge):
        if not net.hasEdge(edge_id):
            raise NetworkError(f"edge {edge_id!r} not found in {net_file}")
        if not net.getEdge(edge_id).allows("passenger"):
            raise NetworkError(f"edge {edge_id!r} in {net_file} does not allow cars")
    path, _cost = net.getShortestPath(
        net.getEdge(from_edge), net.getEdge(to_edge), vClass="passenger"
    )
    if not path:
        raise NetworkError(f"no path for cars from edge {from_edge!r} to {to_edge!r} in {net_file}")
    return tuple(e.getID() for e in path)


def demand_begin_s(demand_file: Path) -> float:
    """The first departure [s] in a route file, plain or gzip-compressed (0 if it has none).

    Raises:
        NetworkError: if the file is missing or not XML, or if a vehicle's type is neither
            defined in the file nor one of SUMO's own (a scenario often defines its types
            in an additional file, which SUMO would not know here).
    """
    if not demand_file.is_file():
        raise NetworkError(f"demand file not found: {demand_file}")
    try:
        with open_xml(demand_file) as stream:
            first, defined, used = _read_demand(stream)
    except (ET.ParseError, OSError, EOFError) as exc:
        raise NetworkError(f"demand file {demand_file} is not XML: {exc}") from None
    unknown = sorted(set(used) - defined - set(SUMO_DEFAULT_TYPES))
    if unknown:
        vtype = unknown[0]
        more = f" and {len(unknown) - 1} more undefined types" if len(unknown) > 1 else ""
        raise NetworkError(
            f"demand file {demand_file}: vehicle {used[vtype]!r} has type {vtype!r}, which the "
            f"file does not define{more}; put the scenario's <vType> definitions (often in an "
            ".add.xml) into it"
        )
    return 0.0 if first == float("inf") else first


def _read_demand(stream: XmlStream) -> tuple[float, set[str], dict[str, str]]:
    """A route file's first departure [s] (``inf`` if none), the vehicle types it defines,
    and the types its vehicles use, each with the first vehicle of it."""
    first = float("inf")
    defined: set[str] = set()
    used: dict[str, str] = {}
    for _event, elem in ET.iterparse(stream, events=("start",)):
        if elem.tag in _TYPE_TAGS:
            defined.add(elem.get("id", ""))
        if elem.tag not in _DEPART_TAGS:
            continue
        vtype = elem.get("type")
        if vtype is not None:
            used.setdefault(vtype, elem.get("id", "?"))
        depart = elem.get("begin" if elem.tag.endswith("Flow") or elem.tag == "flow"
                          else "depart")  # fmt: skip
        try:
            first = min(first, float(depart)) if depart is not None else first
        except ValueError:
            continue  # "triggered" and the like
    return first, defined, used


def own_network(
    net_file: Path,
    route: tuple[str, str],
    cache_dir: Path,
    demand_file: Path | None = None,
) -> ScenarioFiles:
    """A scenario on a network of your own: the route between two edges, the given demand
    (or trips generated over the network), starting where the demand starts.

    Raises:
        NetworkError: naming what cannot be used.
    """
    from explaindrive.sim.route import load_route_geometry

    edges = route_edges(net_file, *route)
    try:
        load_route_geometry(net_file, edges)
    except (ValueError, KeyError) as exc:
        raise NetworkError(f"route {route[0]} -> {route[1]} cannot be driven: {exc}") from None
    demand: tuple[Path, ...]
    if demand_file is not None:
        demand, begin = (demand_file,), demand_begin_s(demand_file)
    else:
        generated_trips(net_file, cache_dir)  # made now: a network without trips fails here
        demand, begin = (), 0.0
    return ScenarioFiles(
        net_file=net_file,
        cache_dir=cache_dir,
        route_edges=edges,
        plan=None,
        demand_files=demand,
        trips=demand_file is None,
        begin_s=begin,
        name=f"{net_file.name}:{route[0]}->{route[1]}",
    )
