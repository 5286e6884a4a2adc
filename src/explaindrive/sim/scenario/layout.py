"""Layout of the urban scenario: the one place that fixes its geometry and demand.

The ego drives eastbound along a two-way main road (one vehicle lane per
direction plus sidewalks) from ``W0`` to ``E0``::

    J1N                                   PXN            J2N
     |                                     :              |
  W0 --- J1 ------ Z1 ------- PX -------- Z2 ---------- J2 --------- E0
     |   (tls)    50|30 km/h  (zebra)   30|50 km/h      (tls + ped   |
    J1S                                   PXS   crossing) J2S

* ``J1``: first signalized intersection; side traffic only crosses the main
  road, so the ego learns light compliance in isolation.
* ``PX``: unsignalized zebra crossing with pedestrian flows; vehicles yield.
* ``J2``: second signalized intersection; side-road traffic turns onto the
  main road ahead of the ego (leading vehicles); a pedestrian crossing on its
  west arm is signalized together with the lights.
* ``Z1`` (with ``priority_junction``): an unsignalised priority junction; a side road
  ``Z1N``-``Z1S`` with right of way (edge priority :data:`PRIORITY_ROAD`, above the main
  road's) crosses the main road, and the ego must yield to its traffic.
* ``T2`` (with ``turn_lane_m``): where the eastbound road widens to two lanes before
  ``J2``: a left-turn lane and a straight-or-right lane (:data:`TURN_LANE_ARROWS`).
* ``K1`` (with ``joined_junction_m``): a signalised junction shortly after ``J1`` with a
  side road ``K1N``-``K1S``; its node joins ``J1``'s light (``tl="J1"``), so one programme
  runs both.
* With ``left_turn`` the ego's route ends on ``J2``'s north arm (``J2_J2N``).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

from explaindrive.sim.scenario.limits import (
    MAX_TRAFFIC_LEVEL,
    SATURATED_LEVEL,
    SEED_LIMIT,
    TRAFFIC_LEVELS,
    validate_seed,
    validate_traffic_level,
)
from explaindrive.sim.scenario.params import SIGNAL_FIXED_S, ScenarioParams

KMH = 1.0 / 3.6  # [m/s per km/h]


@dataclass(frozen=True, slots=True)
class Node:
    """A junction or end point of the plain network."""

    id: str
    x: float  # [m]
    y: float  # [m]
    type: str  # SUMO node type
    tl: str | None = None  # the traffic light it joins (None: its own, if signalised)


@dataclass(frozen=True, slots=True)
class Road:
    """A two-way road between two nodes (one edge per direction)."""

    a: str
    b: str
    speed_mps: float  # [m/s] speed limit
    kind: str = "street"  # "street" (vehicles + sidewalk) or "footpath" (pedestrians only)
    priority: int | None = None
    """netconvert's edge priority of both edges; ``None``: 2 on the main road, 1 elsewhere."""
    forward_lanes: int = 1
    """Vehicle lanes of the edge from ``a`` to ``b`` (the other edge has one)."""

    @property
    def forward(self) -> str:
        """Edge id from ``a`` to ``b``."""
        return f"{self.a}_{self.b}"

    @property
    def backward(self) -> str:
        """Edge id from ``b`` to ``a``."""
        return f"{self.b}_{self.a}"


@dataclass(frozen=True, slots=True)
class Flow:
    """A vehicle flow along a sequence of nodes."""

    id: str
    nodes: tuple[str, ...]
    veh_per_hour: float  # [veh/h] at traffic level 1.0

    @property
    def edges(self) -> tuple[str, ...]:
        """Edge ids of the route."""
        return tuple(f"{a}_{b}" for a, b in pairwise(self.nodes))


@dataclass(frozen=True, slots=True)
class PedestrianFlow:
    """A pedestrian flow walking from one edge to another (across the main road)."""

    id: str
    from_edge: str
    to_edge: str
    persons_per_hour: float  # [1/h], independent of the traffic level
    depart_pos_m: float  # [m] on ``from_edge``
    arrival_pos_m: float  # [m] on ``to_edge``


@dataclass(frozen=True, slots=True)
class LaneConnection:
    """An explicit lane-to-lane connection (a lane's arrow); lane indices count the sidewalk
    (lane 0), so a street's first vehicle lane is 1."""

    from_edge: str
    to_edge: str
    from_lane: int
    to_lane: int


SIDEWALK_WIDTH_M = 2.0  # [m]
SIDE_ROAD_M = 150.0  # [m] length of the side roads at J1 and J2
FOOTPATH_M = 40.0  # [m] length of the footpaths to the zebra
FOOTPATH_SPEED_MPS = 5 * KMH  # [m/s]

EGO_ROUTE_NODES: tuple[str, ...] = ("W0", "J1", "Z1", "PX", "Z2", "J2", "E0")
EGO_ROUTE_EDGES: tuple[str, ...] = tuple(f"{a}_{b}" for a, b in pairwise(EGO_ROUTE_NODES))
TURN_LANE_ARROWS: tuple[tuple[int, str], ...] = ((1, "J2_E0"), (1, "J2_J2S"), (2, "J2_J2N"))
"""(lane of ``T2_J2``, edge it leads to) with a turn lane: the right lane (1, after the
sidewalk) straight and right, the left lane (2) left only."""
TURN_LANE_IN_JUNCTIONS_M = 12.0
"""[m] of the stretch T2-J2 that lies in the two junctions (about 4 m in T2, 7 m in J2), not
on the edge ``T2_J2``."""

# Crossings: (node, edges crossed). The zebra has priority over vehicles; the
# crossing at J2 is controlled by J2's traffic light.
CROSSINGS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("PX", ("Z1_PX", "PX_Z1")),
    ("J2", ("Z2_J2", "J2_Z2")),
)

# Signal timing (static programs, seconds). netconvert builds the phases with these
# settings; their durations and offsets then come from the scenario's parameters.
TLS_CYCLE_S = 60
TLS_YELLOW_S = 3
TLS_ALL_RED_S = 2  # [s] clearance between conflicting streams
MAIN_ROAD_PRIORITY = 2  # netconvert's edge priority of the main road
SIDE_ROAD_PRIORITY = 1  # of the side roads at the lights
PRIORITY_ROAD = 3  # of the side road at a priority junction: above the main road's


@dataclass(frozen=True, slots=True)
class Layout:
    """A scenario of the family as nodes, roads, flows and signal timings."""

    nodes: tuple[Node, ...]
    roads: tuple[Road, ...]
    flows: tuple[Flow, ...]
    pedestrian_flows: tuple[PedestrianFlow, ...]
    tls_phase_durations_s: dict[str, tuple[int, ...]]
    tls_offsets_s: dict[str, int]
    route_nodes: tuple[str, ...] = EGO_ROUTE_NODES
    """The nodes the ego's route passes, first to last."""
    crossings: tuple[tuple[str, tuple[str, ...]], ...] = CROSSINGS
    """Pedestrian crossings: (node, edges crossed)."""
    connections: tuple[LaneConnection, ...] = ()
    """Explicit lane connections (netconvert guesses all others)."""
    joined_tls: tuple[str, ...] = ()
    """Lights that run a cluster of junctions, whose side-road greens are merged into one
    (:func:`~explaindrive.sim.scenario.build.build_network`)."""

    @property
    def route_edges(self) -> tuple[str, ...]:
        """Edge ids of the ego's route."""
        return tuple(f"{a}_{b}" for a, b in pairwise(self.route_nodes))


def _vehicle_flows(params: ScenarioParams, main: tuple[str, ...]) -> tuple[Flow, ...]:
    """The background traffic's flows: the main road (``main``, its nodes west to east) both
    ways, the crossing and turning traffic at J1 and J2, at Z1 with a priority junction, at
    K1 (as many as at J1) and left from a turn lane at J2."""
    d = params.demand
    z1_flows = (
        (Flow("z1_north_south", ("Z1N", "Z1", "Z1S"), d.z1_cross),
         Flow("z1_south_north", ("Z1S", "Z1", "Z1N"), d.z1_cross))
        if params.priority_junction
        else ()
    )  # fmt: skip
    k1_flows = (
        (Flow("k1_north_south", ("K1N", "K1", "K1S"), d.j1_cross),
         Flow("k1_south_north", ("K1S", "K1", "K1N"), d.j1_cross))
        if params.joined_junction_m is not None
        else ()
    )  # fmt: skip
    left = (*_up_to_j2(main), "J2N")
    left_flows = (Flow("j2_west_north", left, d.j2_left),) if params.turn_lane_m else ()
    return (
        Flow("main_east", main, d.main_east),
        Flow("main_west", tuple(reversed(main)), d.main_west),
        Flow("j1_north_south", ("J1N", "J1", "J1S"), d.j1_cross),
        Flow("j1_south_north", ("J1S", "J1", "J1N"), d.j1_cross),
        Flow("j2_south_east", ("J2S", "J2", "E0"), d.j2_turn_south),
        Flow("j2_north_east", ("J2N", "J2", "E0"), d.j2_turn_north),
        Flow("j2_south_north", ("J2S", "J2", "J2N"), d.j2_cross),
        Flow("j2_north_south", ("J2N", "J2", "J2S"), d.j2_cross),
        *z1_flows,
        *k1_flows,
        *left_flows,
    )


def _up_to_j2(main: tuple[str, ...]) -> tuple[str, ...]:
    """The main road's nodes from W0 up to J2."""
    return main[: main.index("J2") + 1]


def _main_road(params: ScenarioParams) -> dict[str, float]:
    """x [m] of the main road's nodes, west to east: those of the paper's road, ``K1`` after
    ``J1`` and ``T2`` before ``J2`` where the scenario has them."""
    blocks = (params.approach_m, params.j1_to_zone_m, params.zone_to_crossing_m,
              params.crossing_to_zone_end_m, params.zone_end_to_j2_m, params.exit_m)  # fmt: skip
    x = dict(zip(EGO_ROUTE_NODES, _cumulative(blocks), strict=True))
    if params.joined_junction_m is not None:
        x["K1"] = x["J1"] + params.joined_junction_m
    if params.turn_lane_m is not None:
        x["T2"] = x["J2"] - params.turn_lane_m
    return dict(sorted(x.items(), key=lambda item: item[1]))


def _nodes(params: ScenarioParams, x: dict[str, float]) -> tuple[Node, ...]:
    """The nodes in file order: the paper's, with Z1's, K1's and T2's where drawn."""
    joined = params.joined_junction_m is not None
    types = {"W0": "dead_end", "J1": "traffic_light", "J2": "traffic_light", "E0": "dead_end",
             "K1": "traffic_light"}  # fmt: skip
    tl = {"J1": "J1", "K1": "J1"} if joined else {}
    nodes = [Node(n, xn, 0.0, types.get(n, "priority"), tl.get(n)) for n, xn in x.items()]
    ends = (("N", SIDE_ROAD_M), ("S", -SIDE_ROAD_M))
    for n, y in ends:
        nodes.append(Node(f"J1{n}", x["J1"], y, "dead_end"))
        nodes.append(Node(f"PX{n}", x["PX"], FOOTPATH_M if y > 0 else -FOOTPATH_M, "dead_end"))
        nodes.append(Node(f"J2{n}", x["J2"], y, "dead_end"))
    for junction, drawn in (("Z1", params.priority_junction), ("K1", joined)):
        if drawn:
            nodes += [Node(f"{junction}{n}", x[junction], y, "dead_end") for n, y in ends]
    order = ("W0", "J1", "J1N", "J1S", "K1", "K1N", "K1S", "Z1", "Z1N", "Z1S", "PX", "PXN",
             "PXS", "Z2", "T2", "J2", "J2N", "J2S", "E0")  # fmt: skip
    by_id = {n.id: n for n in nodes}
    return tuple(by_id[n] for n in order if n in by_id)


def _roads(params: ScenarioParams, x: dict[str, float]) -> list[Road]:
    """The main road's blocks (the zone's limit from Z1 to Z2), then the side roads, the
    footpaths to the zebra and the side roads of Z1 and K1 where drawn."""
    main, zone, side = (params.limit_kmh * KMH, params.zone_limit_kmh * KMH,
                        params.side_limit_kmh * KMH)  # fmt: skip
    roads = []
    for a, b in pairwise(x):
        in_zone = x["Z1"] <= x[a] and x[b] <= x["Z2"]
        lanes = 2 if (a, b) == ("T2", "J2") else 1
        priority = MAIN_ROAD_PRIORITY if a not in EGO_ROUTE_NODES else None
        roads.append(Road(a, b, zone if in_zone else main, priority=priority,
                          forward_lanes=lanes))  # fmt: skip
    roads += [Road(f"{j}{n}", j, side) for j in ("J1", "J2") for n in ("N", "S")]
    roads += [Road(f"PX{n}", "PX", FOOTPATH_SPEED_MPS, kind="footpath") for n in ("S", "N")]
    if params.priority_junction:
        roads += [Road(f"Z1{n}", "Z1", side, priority=PRIORITY_ROAD) for n in ("N", "S")]
    if params.joined_junction_m is not None:
        roads += [Road(f"K1{n}", "K1", side) for n in ("N", "S")]
    return roads


def _pedestrian_flows(params: ScenarioParams, j2_in: str) -> tuple[PedestrianFlow, ...]:
    """The zebra's and J2's pedestrians; those at J2 walk along the main road's edge
    ``j2_in`` into J2 (and its opposite)."""
    zebra, j2 = params.zebra_peds_per_hour, params.j2_peds_per_hour
    block = params.zone_end_to_j2_m  # [m] the stretch ``j2_in`` covers
    if params.turn_lane_m is not None:
        block = params.turn_lane_m - TURN_LANE_IN_JUNCTIONS_M
    # pedestrians at J2 walk from 150 m (at most 3/4 of the block) to 50 m (at most half)
    # along the edge they start and end on
    j2_depart, j2_arrival = min(150.0, 0.75 * block), min(50.0, block / 2)
    j2_out = "_".join(reversed(j2_in.split("_")))
    peds = (
        PedestrianFlow("zebra_northbound", "PXS_PX", "PX_PXN", zebra, 5.0, 20.0),
        PedestrianFlow("zebra_southbound", "PXN_PX", "PX_PXS", zebra, 5.0, 20.0),
        PedestrianFlow("j2_northbound", j2_in, j2_out, j2, j2_depart, j2_arrival),
        PedestrianFlow("j2_southbound", j2_out, j2_in, j2, j2_depart, j2_arrival),
    )
    return tuple(p for p in peds if p.persons_per_hour > 0)


def make_layout(params: ScenarioParams) -> Layout:
    """The nodes, roads, flows and signal timings of a scenario of the family."""
    x = _main_road(params)
    main = tuple(x)
    j2_in = f"{main[main.index('J2') - 1]}_J2"
    route = (*_up_to_j2(main), "J2N" if params.left_turn else "E0")
    connections: tuple[LaneConnection, ...] = ()
    if params.turn_lane_m is not None:
        connections = tuple(LaneConnection("Z2_T2", "T2_J2", 1, lane) for lane in (1, 2))
        connections += tuple(LaneConnection("T2_J2", to, lane, 1)
                             for lane, to in TURN_LANE_ARROWS)  # fmt: skip
    return Layout(
        nodes=_nodes(params, x),
        roads=tuple(_roads(params, x)),
        flows=_vehicle_flows(params, main),
        pedestrian_flows=_pedestrian_flows(params, j2_in),
        tls_phase_durations_s={
            "J1": params.j1.durations(SIGNAL_FIXED_S["J1"]),
            "J2": params.j2.durations(SIGNAL_FIXED_S["J2"]),
        },
        tls_offsets_s={"J1": params.j1.offset_s, "J2": params.j2.offset_s},
        route_nodes=route,
        crossings=(CROSSINGS[0], ("J2", (j2_in, "_".join(reversed(j2_in.split("_")))))),
        connections=connections,
        joined_tls=("J1",) if params.joined_junction_m is not None else (),
    )


def _cumulative(blocks: tuple[float, ...]) -> list[float]:
    xs = [0.0]
    for b in blocks:
        xs.append(xs[-1] + b)
    return xs


PAPER_LAYOUT = make_layout(ScenarioParams())
"""The paper's road."""
NODES = PAPER_LAYOUT.nodes
ROADS = PAPER_LAYOUT.roads
FLOWS = PAPER_LAYOUT.flows
PEDESTRIAN_FLOWS = PAPER_LAYOUT.pedestrian_flows
TLS_PHASE_DURATIONS_S = PAPER_LAYOUT.tls_phase_durations_s

__all__ = [
    "CROSSINGS",
    "EGO_ROUTE_EDGES",
    "EGO_ROUTE_NODES",
    "FLOWS",
    "KMH",
    "MAX_TRAFFIC_LEVEL",
    "NODES",
    "PAPER_LAYOUT",
    "PEDESTRIAN_FLOWS",
    "ROADS",
    "SATURATED_LEVEL",
    "SEED_LIMIT",
    "TRAFFIC_LEVELS",
    "Layout",
    "make_layout",
    "validate_seed",
    "validate_traffic_level",
]
