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


@dataclass(frozen=True, slots=True)
class Road:
    """A two-way road between two nodes (one edge per direction)."""

    a: str
    b: str
    speed_mps: float  # [m/s] speed limit
    kind: str = "street"  # "street" (vehicles + sidewalk) or "footpath" (pedestrians only)
    priority: int | None = None
    """netconvert's edge priority of both edges; ``None``: 2 on the main road, 1 elsewhere."""

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


SIDEWALK_WIDTH_M = 2.0  # [m]
SIDE_ROAD_M = 150.0  # [m] length of the side roads at J1 and J2
FOOTPATH_M = 40.0  # [m] length of the footpaths to the zebra
FOOTPATH_SPEED_MPS = 5 * KMH  # [m/s]

EGO_ROUTE_NODES: tuple[str, ...] = ("W0", "J1", "Z1", "PX", "Z2", "J2", "E0")
EGO_ROUTE_EDGES: tuple[str, ...] = tuple(f"{a}_{b}" for a, b in pairwise(EGO_ROUTE_NODES))

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


def _vehicle_flows(params: ScenarioParams) -> tuple[Flow, ...]:
    """The background traffic's flows: the main road both ways, the crossing and turning
    traffic at J1 and J2, and at Z1 with a priority junction."""
    d = params.demand
    z1_flows = (
        (Flow("z1_north_south", ("Z1N", "Z1", "Z1S"), d.z1_cross),
         Flow("z1_south_north", ("Z1S", "Z1", "Z1N"), d.z1_cross))
        if params.priority_junction
        else ()
    )  # fmt: skip
    return (
        Flow("main_east", EGO_ROUTE_NODES, d.main_east),
        Flow("main_west", tuple(reversed(EGO_ROUTE_NODES)), d.main_west),
        Flow("j1_north_south", ("J1N", "J1", "J1S"), d.j1_cross),
        Flow("j1_south_north", ("J1S", "J1", "J1N"), d.j1_cross),
        Flow("j2_south_east", ("J2S", "J2", "E0"), d.j2_turn_south),
        Flow("j2_north_east", ("J2N", "J2", "E0"), d.j2_turn_north),
        Flow("j2_south_north", ("J2S", "J2", "J2N"), d.j2_cross),
        Flow("j2_north_south", ("J2N", "J2", "J2S"), d.j2_cross),
        *z1_flows,
    )


def make_layout(params: ScenarioParams) -> Layout:
    """The nodes, roads, flows and signal timings of a scenario of the family."""
    blocks = (params.approach_m, params.j1_to_zone_m, params.zone_to_crossing_m,
              params.crossing_to_zone_end_m, params.zone_end_to_j2_m, params.exit_m)  # fmt: skip
    x = dict(zip(EGO_ROUTE_NODES, _cumulative(blocks), strict=True))
    main, zone, side = (params.limit_kmh * KMH, params.zone_limit_kmh * KMH,
                        params.side_limit_kmh * KMH)  # fmt: skip
    types = {"W0": "dead_end", "J1": "traffic_light", "J2": "traffic_light", "E0": "dead_end"}
    nodes = [Node(n, x[n], 0.0, types.get(n, "priority")) for n in EGO_ROUTE_NODES]
    for n, y in (("N", SIDE_ROAD_M), ("S", -SIDE_ROAD_M)):
        nodes.append(Node(f"J1{n}", x["J1"], y, "dead_end"))
        nodes.append(Node(f"PX{n}", x["PX"], FOOTPATH_M if y > 0 else -FOOTPATH_M, "dead_end"))
        nodes.append(Node(f"J2{n}", x["J2"], y, "dead_end"))
    z1_side = ("Z1N", "Z1S") if params.priority_junction else ()
    if params.priority_junction:
        nodes += [Node(n, x["Z1"], y, "dead_end") for n, y in zip(z1_side, (SIDE_ROAD_M,
                  -SIDE_ROAD_M), strict=True)]  # fmt: skip
    order = ("W0", "J1", "J1N", "J1S", "Z1", *z1_side, "PX", "PXN", "PXS", "Z2", "J2", "J2N",
             "J2S", "E0")  # fmt: skip
    by_id = {n.id: n for n in nodes}
    limits = (main, main, zone, zone, main, main)
    roads = [Road(a, b, v) for (a, b), v in zip(pairwise(EGO_ROUTE_NODES), limits, strict=True)]
    roads += [Road(f"{j}{n}", j, side) for j in ("J1", "J2") for n in ("N", "S")]
    roads += [Road(f"PX{n}", "PX", FOOTPATH_SPEED_MPS, kind="footpath") for n in ("S", "N")]
    roads += [Road(n, "Z1", side, priority=PRIORITY_ROAD) for n in z1_side]
    flows = _vehicle_flows(params)
    zebra, j2 = params.zebra_peds_per_hour, params.j2_peds_per_hour
    # pedestrians at J2 walk along the block Z2-J2 from 150 m (at most 3/4 of it) to 50 m
    # (at most half of it) along the edge they start and end on
    j2_depart = min(150.0, 0.75 * params.zone_end_to_j2_m)
    j2_arrival = min(50.0, params.zone_end_to_j2_m / 2)
    peds = (
        PedestrianFlow("zebra_northbound", "PXS_PX", "PX_PXN", zebra, 5.0, 20.0),
        PedestrianFlow("zebra_southbound", "PXN_PX", "PX_PXS", zebra, 5.0, 20.0),
        PedestrianFlow("j2_northbound", "Z2_J2", "J2_Z2", j2, j2_depart, j2_arrival),
        PedestrianFlow("j2_southbound", "J2_Z2", "Z2_J2", j2, j2_depart, j2_arrival),
    )
    return Layout(
        nodes=tuple(by_id[n] for n in order),
        roads=tuple(roads),
        flows=flows,
        pedestrian_flows=tuple(p for p in peds if p.persons_per_hour > 0),
        tls_phase_durations_s={
            "J1": params.j1.durations(SIGNAL_FIXED_S["J1"]),
            "J2": params.j2.durations(SIGNAL_FIXED_S["J2"]),
        },
        tls_offsets_s={"J1": params.j1.offset_s, "J2": params.j2.offset_s},
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
