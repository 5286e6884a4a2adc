"""Geometry of the ego route read from a SUMO network: positions of stop lines,
crossings and speed-limit zones measured along the route.

Route positions are in metres from the start of the first route edge and
include the internal (junction) lanes, so they match SUMO's odometer.
"""

from __future__ import annotations

import bisect
import itertools
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

POSTED_DECEL_MPS2 = 0.75  # [m/s^2] the posted limit ramps down to a lower zone at this rate


@dataclass(frozen=True, slots=True)
class RouteLight:
    """A traffic light on the route."""

    tls_id: str
    stop_line_m: float  # [m] route position of the stop line
    lane_links: tuple[tuple[str, int], ...] = ()
    """(approach lane, index of its link in the light's state) for every lane that leads on
    along the route (several on a multi-lane road)."""

    def link_of(self, lane_id: str) -> int | None:
        """The index of the link the ego follows from ``lane_id`` (``None``: not an
        approach lane of this light)."""
        for lane, index in self.lane_links:
            if lane == lane_id:
                return index
        return None


@dataclass(frozen=True, slots=True)
class RouteCrossing:
    """A pedestrian crossing over the route."""

    crossing_edge: str  # SUMO internal edge id of the crossing (":PX_c0")
    walkingareas: tuple[str, ...]  # walking areas from which pedestrians enter it
    stop_line_m: float  # [m] route position where the ego must stop for it
    signalized: bool
    end_m: float  # [m] route position where the junction holding it ends
    approach_edge: str = ""  # the route edge that leads to it


@dataclass(frozen=True, slots=True)
class RouteGeometry:
    """Static geometry of the ego route."""

    edges: tuple[str, ...]
    edge_start_m: tuple[float, ...]  # [m] route position of each edge's start
    length_m: float  # [m] route position of the end of the last edge
    zone_start_m: tuple[float, ...]  # [m] start of each constant-limit stretch
    zone_limit_mps: tuple[float, ...]  # [m/s] its limit
    lights: tuple[RouteLight, ...]
    crossings: tuple[RouteCrossing, ...]

    def limit_at(self, pos_m: float) -> float:
        """Legal speed limit [m/s] at a route position."""
        i = bisect.bisect_right(self.zone_start_m, pos_m) - 1
        return self.zone_limit_mps[max(i, 0)]

    def posted_limit(self, pos_m: float, decel_mps2: float = POSTED_DECEL_MPS2) -> float:
        """Limit the driver must respect at ``pos_m``: the legal limit, lowered before each
        lower zone ``d`` metres ahead to the speed v from which braking at ``b`` =
        ``decel_mps2`` still reaches the zone's limit at its start after this step's travel,
        v^2 + 2 b v = v_zone^2 + 2 b d, and never below the zone's limit.

        This models speed-limit signs seen in time: a driver who keeps to the posted limit
        slows down for a lower zone by at most 1 m/s per 1 s step and is within the zone's
        limit once in it (``tests/sim/test_route.py`` drives it).
        """
        here = bisect.bisect_right(self.zone_start_m, pos_m) - 1
        limit = self.zone_limit_mps[max(here, 0)]
        for start, zone_limit in zip(
            self.zone_start_m[here + 1 :], self.zone_limit_mps[here + 1 :], strict=True
        ):
            if zone_limit < limit:
                b = decel_mps2
                reach = zone_limit * zone_limit + 2.0 * b * (start - pos_m)
                ramp = -b + math.sqrt(b * b + reach) if reach > 0.0 else 0.0
                limit = min(limit, max(zone_limit, ramp))
        return limit


def _lane_lengths(root: ET.Element) -> dict[str, tuple[float, float]]:
    out: dict[str, tuple[float, float]] = {}
    for edge in root.iter("edge"):
        for lane in edge.iter("lane"):
            out[lane.attrib["id"]] = (float(lane.attrib["length"]), float(lane.attrib["speed"]))
    return out


def load_route_geometry(net_file: Path, route_edges: tuple[str, ...]) -> RouteGeometry:
    """Read the ego route's geometry from a network file.

    Raises:
        ValueError: if the route is not drivable in the network.
    """
    root = ET.parse(net_file).getroot()
    net = _Network.read(root)
    layout = _lay_out(net, route_edges, net_file)
    edge_to = {e.attrib["id"]: e.get("to") for e in root.iter("edge") if not e.get("function")}
    nodes = {j.attrib["id"]: j for j in root.iter("junction")}
    lights = [
        RouteLight(
            tls_id=tls_id,
            stop_line_m=layout.end[eid],
            lane_links=tuple(net.links.get((eid, nxt), ())),
        )
        for eid, nxt in itertools.pairwise(route_edges)
        if (tls_id := net.conns[(eid, nxt)].get("tl"))
    ]
    crossings = _route_crossings(root, route_edges, edge_to, nodes, layout)
    return RouteGeometry(
        edges=tuple(route_edges),
        edge_start_m=tuple(layout.starts),
        length_m=layout.length_m,
        zone_start_m=tuple(layout.zone_start),
        zone_limit_mps=tuple(layout.zone_limit),
        lights=tuple(lights),
        crossings=tuple(crossings),
    )


@dataclass
class _Network:
    """What the route layout needs from a network file."""

    lanes: dict[str, tuple[float, float]]  # lane -> (length, speed limit)
    edge_lane: dict[str, str]  # normal edge -> its vehicle lane
    conns: dict[tuple[str, str], ET.Element]  # (edge, next edge) -> connection with a via lane
    via_next: dict[str, str]  # internal lane -> the next internal lane
    links: dict[tuple[str, str], list[tuple[str, int]]]  # (edge, next) -> signalled links

    @classmethod
    def read(cls, root: ET.Element) -> _Network:
        edge_lane: dict[str, str] = {}
        car_lanes: set[str] = set()
        for edge in root.iter("edge"):
            if edge.get("function"):
                continue
            for lane in edge.iter("lane"):
                if _allows_cars(lane):
                    car_lanes.add(lane.attrib["id"])
                    edge_lane[edge.attrib["id"]] = lane.attrib["id"]  # the leftmost car lane
        conns: dict[tuple[str, str], ET.Element] = {}
        links: dict[tuple[str, str], list[tuple[str, int]]] = {}
        via_next: dict[str, str] = {}
        for c in root.iter("connection"):
            src, dst = c.attrib["from"], c.attrib["to"]
            if src.startswith(":"):
                if c.get("via"):
                    via_next[f"{src}_{c.attrib['fromLane']}"] = c.attrib["via"]
                continue
            lane_from = f"{src}_{c.attrib['fromLane']}"
            # the reference lane's connection, else the first car lane's (several lanes)
            usable = dst in edge_lane and lane_from in car_lanes
            if usable and (lane_from == edge_lane.get(src) or (src, dst) not in conns):
                conns[(src, dst)] = c
            if usable and c.get("tl") and c.get("linkIndex") is not None:
                links.setdefault((src, dst), []).append((lane_from, int(c.attrib["linkIndex"])))
        return cls(_lane_lengths(root), edge_lane, conns, via_next, links)


def _allows_cars(lane: ET.Element) -> bool:
    """Whether a lane of a normal edge carries passenger cars (not a sidewalk or bike lane)."""
    allow, disallow = lane.get("allow"), lane.get("disallow")
    if allow is not None:
        return "passenger" in allow.split() or allow == "all"
    return disallow is None or "passenger" not in disallow.split()


@dataclass
class _Layout:
    """Positions along the route [m]: edge starts and ends, speed zones, total length."""

    starts: list[float]
    end: dict[str, float]
    zone_start: list[float]
    zone_limit: list[float]
    length_m: float


def _lay_out(net: _Network, route_edges: tuple[str, ...], net_file: Path) -> _Layout:
    """Walk the route edge by edge, through the junctions' internal lanes."""
    layout = _Layout([], {}, [], [], 0.0)
    pos = 0.0
    for i, eid in enumerate(route_edges):
        if eid not in net.edge_lane:
            raise ValueError(f"route edge {eid!r} not found in {net_file}")
        length, speed = net.lanes[net.edge_lane[eid]]
        layout.starts.append(pos)
        if not layout.zone_limit or layout.zone_limit[-1] != speed:
            layout.zone_start.append(pos)
            layout.zone_limit.append(speed)
        pos += length
        layout.end[eid] = pos
        if i + 1 < len(route_edges):
            conn = net.conns.get((eid, route_edges[i + 1]))
            if conn is None:
                raise ValueError(f"no connection {eid} -> {route_edges[i + 1]} in {net_file}")
            via: str | None = conn.get("via")
            nxt_speed = net.lanes[net.edge_lane[route_edges[i + 1]]][1]
            if nxt_speed < speed:  # the lower limit starts at the junction
                layout.zone_start.append(pos)
                layout.zone_limit.append(nxt_speed)
            while via:
                pos += net.lanes[via][0]
                via = net.via_next.get(via)
    layout.length_m = pos
    return layout


def _route_crossings(
    root: ET.Element,
    route_edges: tuple[str, ...],
    edge_to: dict[str, str | None],
    nodes: dict[str, ET.Element],
    layout: _Layout,
) -> list[RouteCrossing]:
    """The pedestrian crossings over the route, ordered along it."""
    crossings = []
    for edge in root.iter("edge"):
        if edge.get("function") != "crossing":
            continue
        crossed = set((edge.get("crossingEdges") or "").split())
        cid = edge.attrib["id"]
        node_id = cid[1:].rsplit("_", 1)[0]
        route_in = [e for e in route_edges[:-1] if edge_to[e] == node_id]
        if not crossed & set(route_edges) or not route_in:
            continue
        walk = sorted(
            {c.attrib["from"] for c in root.iter("connection") if c.attrib["to"] == cid}
            | {c.attrib["to"] for c in root.iter("connection") if c.attrib["from"] == cid}
        )
        crossings.append(
            RouteCrossing(
                crossing_edge=cid,
                walkingareas=tuple(walk),
                stop_line_m=layout.end[route_in[0]],
                signalized=nodes[node_id].get("type") == "traffic_light",
                end_m=layout.starts[route_edges.index(route_in[0]) + 1],
                approach_edge=route_in[0],
            )
        )
    return sorted(crossings, key=lambda c: c.stop_line_m)
