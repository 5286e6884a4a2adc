"""Geometry of the ego route read from a SUMO network: positions of stop lines,
crossings and speed-limit zones measured along the route.

Route positions are in metres from the start of the first route edge and
include the internal (junction) lanes, so they match SUMO's odometer. The network is read
with sumolib, as the scene (:mod:`explaindrive.sim.scene`) and the crossing lanes
(:mod:`explaindrive.sim.crossing_lanes`) read it.
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import sumolib

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
class RouteJunction:
    """A junction the route passes, from its stop line to where its next edge starts."""

    node_id: str
    start_m: float  # [m] route position of the stop line (the end of the edge into it)
    end_m: float  # [m] route position of the start of the edge out of it
    signalized: bool  # a traffic light controls it
    crossing: bool  # a pedestrian crossing over the route lies on it


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
    junctions: tuple[RouteJunction, ...] = ()
    edge_stop_m: tuple[float, ...] = ()  # [m] route position of each edge's end (its stop line)

    def edge_end_m(self, index: int) -> float:
        """[m] The route position of the end of route edge ``index`` (the stop line before
        the next junction; a geometry without ``edge_stop_m``: the next edge's start, or the
        route's end)."""
        if self.edge_stop_m:
            return self.edge_stop_m[index]
        starts = self.edge_start_m
        return starts[index + 1] if index + 1 < len(starts) else self.length_m

    def junction_at(self, pos_m: float) -> RouteJunction | None:
        """The junction whose area (stop line to the next edge) holds ``pos_m``, if any."""
        for junction in self.junctions:
            if junction.start_m <= pos_m < junction.end_m:
                return junction
        return None

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


def read_net(net_file: str | Path) -> Any:
    """The network as sumolib reads it, with internal lanes and pedestrian connections: the
    one way the route, the crossing lanes, the scene and the plots read a network (sumolib's
    objects are untyped, hence ``Any``)."""
    return sumolib.net.readNet(str(net_file), withInternal=True, withPedestrianConnections=True)


def load_route_geometry(
    net_file: Path, route_edges: tuple[str, ...], net: Any | None = None
) -> RouteGeometry:
    """Read the ego route's geometry from a network file.

    Args:
        net_file: the SUMO network.
        route_edges: the ego's route.
        net: ``net_file`` as :func:`read_net` read it, if the caller already has it.

    Raises:
        ValueError: if the route is not drivable in the network.
    """
    net = read_net(net_file) if net is None else net
    road = _CarLanes.read(net)
    layout = _lay_out(net, road, route_edges, net_file)
    lights = [
        RouteLight(
            tls_id=tls_id,
            stop_line_m=layout.end[eid],
            lane_links=tuple(road.links.get((eid, nxt), ())),
        )
        for eid, nxt in itertools.pairwise(route_edges)
        if (tls_id := road.conns[(eid, nxt)].getTLSID())
    ]
    crossings = _route_crossings(net, route_edges, layout)
    return RouteGeometry(
        edges=tuple(route_edges),
        edge_start_m=tuple(layout.starts),
        length_m=layout.length_m,
        zone_start_m=tuple(layout.zone_start),
        zone_limit_mps=tuple(layout.zone_limit),
        lights=tuple(lights),
        crossings=tuple(crossings),
        junctions=tuple(_route_junctions(net, route_edges, layout, crossings)),
        edge_stop_m=tuple(layout.ends),
    )


@dataclass
class _CarLanes:
    """Where a route of cars runs in a network: its lane on each edge and its connections.

    sumolib's lanes, connections and edges are untyped, hence ``Any``.
    """

    edge_lane: dict[str, Any]  # normal edge -> its leftmost car lane
    conns: dict[tuple[str, str], Any]  # (edge, next edge) -> the connection the route takes
    links: dict[tuple[str, str], list[tuple[str, int]]]  # (edge, next) -> signalled links

    @classmethod
    def read(cls, net: Any) -> _CarLanes:
        edges = net.getEdges(withInternal=False)
        edge_lane: dict[str, Any] = {}
        for edge in edges:
            for lane in edge.getLanes():
                if lane.allows("passenger"):
                    edge_lane[edge.getID()] = lane  # the last one is the leftmost car lane
        conns: dict[tuple[str, str], Any] = {}
        links: dict[tuple[str, str], list[tuple[str, int]]] = {}
        for edge in edges:
            for to_edge, candidates in edge.getOutgoing().items():
                key = (edge.getID(), to_edge.getID())
                if key[1] not in edge_lane:
                    continue
                for conn in candidates:  # in the file's order
                    lane = conn.getFromLane()
                    if not lane.allows("passenger"):
                        continue
                    # the reference lane's connection, else the first car lane's
                    if lane is edge_lane[key[0]] or key not in conns:
                        conns[key] = conn
                    if conn.getTLSID():
                        links.setdefault(key, []).append((lane.getID(), conn.getTLLinkIndex()))
        return cls(edge_lane, conns, links)


@dataclass
class _Layout:
    """Positions along the route [m]: edge starts and ends, speed zones, total length."""

    starts: list[float]
    ends: list[float]
    end: dict[str, float]
    zone_start: list[float]
    zone_limit: list[float]
    length_m: float


def _lay_out(net: Any, road: _CarLanes, route_edges: tuple[str, ...], net_file: Path) -> _Layout:
    """Walk the route edge by edge, through the junctions' internal lanes."""
    layout = _Layout([], [], {}, [], [], 0.0)
    pos = 0.0
    for i, eid in enumerate(route_edges):
        if eid not in road.edge_lane:
            raise ValueError(f"route edge {eid!r} not found in {net_file}")
        lane = road.edge_lane[eid]
        speed = lane.getSpeed()
        layout.starts.append(pos)
        if not layout.zone_limit or layout.zone_limit[-1] != speed:
            layout.zone_start.append(pos)
            layout.zone_limit.append(speed)
        pos += lane.getLength()
        layout.end[eid] = pos
        layout.ends.append(pos)
        if i + 1 < len(route_edges):
            conn = road.conns.get((eid, route_edges[i + 1]))
            if conn is None:
                raise ValueError(f"no connection {eid} -> {route_edges[i + 1]} in {net_file}")
            nxt_speed = road.edge_lane[route_edges[i + 1]].getSpeed()
            if nxt_speed < speed:  # the lower limit starts at the junction
                layout.zone_start.append(pos)
                layout.zone_limit.append(nxt_speed)
            for via in _via_lanes(net, conn):
                pos += via.getLength()
    layout.length_m = pos
    return layout


def _via_lanes(net: Any, conn: Any) -> Iterator[Any]:
    """The internal lanes a connection runs through its junction, in order."""
    via_id = conn.getViaLaneID()
    while via_id:
        lane = net.getLane(via_id)
        yield lane
        onward = [c.getViaLaneID() for c in lane.getOutgoing() if c.getViaLaneID()]
        via_id = onward[-1] if onward else ""


def _route_junctions(
    net: Any, route_edges: tuple[str, ...], layout: _Layout, crossings: list[RouteCrossing]
) -> list[RouteJunction]:
    """The junctions between the route's edges, in route order."""
    zebra_edges = {c.approach_edge for c in crossings}
    junctions = []
    for i, (eid, _nxt) in enumerate(itertools.pairwise(route_edges)):
        node = net.getEdge(eid).getToNode()
        junctions.append(RouteJunction(
            node_id=node.getID(), start_m=layout.end[eid], end_m=layout.starts[i + 1],
            signalized=node.getType().startswith("traffic_light"), crossing=eid in zebra_edges,
        ))  # fmt: skip
    return junctions


def _route_crossings(
    net: Any, route_edges: tuple[str, ...], layout: _Layout
) -> list[RouteCrossing]:
    """The pedestrian crossings over the route, ordered along it."""
    on_route = set(route_edges)
    crossings = []
    for edge in net.getEdges():
        if edge.getFunction() != "crossing":
            continue
        node = edge.getFromNode()  # the crossing's junction
        route_in = [
            e for e in route_edges[:-1] if net.getEdge(e).getToNode().getID() == node.getID()
        ]
        crossed = {e.getID() for e in edge.getCrossingEdges()}
        if not crossed & on_route or not route_in:
            continue
        walk = sorted(
            {e.getID() for e in edge.getIncoming()} | {e.getID() for e in edge.getOutgoing()}
        )
        crossings.append(
            RouteCrossing(
                crossing_edge=edge.getID(),
                walkingareas=tuple(walk),
                stop_line_m=layout.end[route_in[0]],
                signalized=node.getType() == "traffic_light",
                end_m=layout.starts[route_edges.index(route_in[0]) + 1],
                approach_edge=route_in[0],
            )
        )
    return sorted(crossings, key=lambda c: c.stop_line_m)
