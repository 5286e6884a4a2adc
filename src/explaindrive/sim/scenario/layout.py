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
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

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


SPEED_50 = 50 * KMH  # [m/s]
SPEED_30 = 30 * KMH  # [m/s]
SIDE_SPEED = 50 * KMH  # [m/s]
SIDEWALK_WIDTH_M = 2.0  # [m]

NODES: tuple[Node, ...] = (
    Node("W0", 0.0, 0.0, "dead_end"),
    Node("J1", 400.0, 0.0, "traffic_light"),
    Node("J1N", 400.0, 150.0, "dead_end"),
    Node("J1S", 400.0, -150.0, "dead_end"),
    Node("Z1", 600.0, 0.0, "priority"),
    Node("PX", 800.0, 0.0, "priority"),
    Node("PXN", 800.0, 40.0, "dead_end"),
    Node("PXS", 800.0, -40.0, "dead_end"),
    Node("Z2", 1000.0, 0.0, "priority"),
    Node("J2", 1200.0, 0.0, "traffic_light"),
    Node("J2N", 1200.0, 150.0, "dead_end"),
    Node("J2S", 1200.0, -150.0, "dead_end"),
    Node("E0", 1550.0, 0.0, "dead_end"),
)

ROADS: tuple[Road, ...] = (
    Road("W0", "J1", SPEED_50),
    Road("J1", "Z1", SPEED_50),
    Road("Z1", "PX", SPEED_30),
    Road("PX", "Z2", SPEED_30),
    Road("Z2", "J2", SPEED_50),
    Road("J2", "E0", SPEED_50),
    Road("J1N", "J1", SIDE_SPEED),
    Road("J1S", "J1", SIDE_SPEED),
    Road("J2N", "J2", SIDE_SPEED),
    Road("J2S", "J2", SIDE_SPEED),
    Road("PXS", "PX", 5 * KMH, kind="footpath"),
    Road("PXN", "PX", 5 * KMH, kind="footpath"),
)

# Crossings: (node, edges crossed). The zebra has priority over vehicles; the
# crossing at J2 is controlled by J2's traffic light.
CROSSINGS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("PX", ("Z1_PX", "PX_Z1")),
    ("J2", ("Z2_J2", "J2_Z2")),
)

EGO_ROUTE_NODES: tuple[str, ...] = ("W0", "J1", "Z1", "PX", "Z2", "J2", "E0")
EGO_ROUTE_EDGES: tuple[str, ...] = tuple(f"{a}_{b}" for a, b in pairwise(EGO_ROUTE_NODES))

# Main-road eastbound demand at traffic level 1.0: one vehicle every 4 s.
MAIN_DEMAND_VEH_PER_HOUR = 900.0

FLOWS: tuple[Flow, ...] = (
    Flow("main_east", EGO_ROUTE_NODES, MAIN_DEMAND_VEH_PER_HOUR),
    Flow("main_west", tuple(reversed(EGO_ROUTE_NODES)), 450.0),
    Flow("j1_north_south", ("J1N", "J1", "J1S"), 150.0),
    Flow("j1_south_north", ("J1S", "J1", "J1N"), 150.0),
    Flow("j2_south_east", ("J2S", "J2", "E0"), 180.0),
    Flow("j2_north_east", ("J2N", "J2", "E0"), 120.0),
    Flow("j2_south_north", ("J2S", "J2", "J2N"), 60.0),
    Flow("j2_north_south", ("J2N", "J2", "J2S"), 60.0),
)

PEDESTRIAN_FLOWS: tuple[PedestrianFlow, ...] = (
    PedestrianFlow("zebra_northbound", "PXS_PX", "PX_PXN", 90.0, 5.0, 20.0),
    PedestrianFlow("zebra_southbound", "PXN_PX", "PX_PXS", 90.0, 5.0, 20.0),
    PedestrianFlow("j2_northbound", "Z2_J2", "J2_Z2", 120.0, 150.0, 50.0),
    PedestrianFlow("j2_southbound", "J2_Z2", "Z2_J2", 120.0, 150.0, 50.0),
)

# Signal timing (static programs, seconds). netconvert builds the phases; their
# durations are then set here: the main road gets most of the 60 s cycle so that
# it carries its demand up to about traffic level 1.5.
TLS_CYCLE_S = 60
TLS_YELLOW_S = 3
TLS_ALL_RED_S = 2  # [s] clearance between conflicting streams
TLS_OFFSET_J2_S = 25  # [s] offset of J2 against J1 (a partial green wave)
TLS_PHASE_DURATIONS_S: dict[str, tuple[int, ...]] = {
    "J1": (37, 3, 2, 13, 3, 2),  # main green, yellow, all red, side green, yellow, all red
    # main green, yellow, all red, side + pedestrians, side only, yellow, all red
    "J2": (34, 3, 2, 13, 3, 3, 2),
}


def traffic_level_demand(level: float) -> float:
    """Main-road eastbound demand [veh/h] at a traffic level (1.0 = 900 veh/h).

    Raises:
        ValueError: if ``level`` is not a positive finite number.
    """
    validate_traffic_level(level)
    return MAIN_DEMAND_VEH_PER_HOUR * level


TRAFFIC_LEVELS: tuple[float, ...] = (0.5, 0.75, 1.0, 1.25, 1.5)
"""The paper's five traffic levels (1.0 = 900 veh/h on the main road)."""
MAX_TRAFFIC_LEVEL = 1.75
"""The busiest level the scenario accepts: at 1.75 the ego entered the road in every one of
seeds 0-49; at 2.0 the first road stayed blocked in 5 of seeds 0-29."""
SEED_LIMIT = 2**31
"""SUMO's seeds are integers in [0, SEED_LIMIT)."""


def validate_traffic_level(level: float) -> float:
    """Return ``level`` as a float if it is in (0, :data:`MAX_TRAFFIC_LEVEL`].

    Raises:
        ValueError: naming the range, otherwise.
    """
    import math

    if isinstance(level, bool) or not isinstance(level, int | float) or not math.isfinite(level):
        raise ValueError(f"traffic level must be a finite number > 0, got {level!r}")
    if level <= 0:
        raise ValueError(f"traffic level must be > 0, got {level:g}")
    if level > MAX_TRAFFIC_LEVEL:
        raise ValueError(
            f"traffic level must be at most {MAX_TRAFFIC_LEVEL:g}, got {level:g}: on a busier "
            "road the ego cannot enter"
        )
    return float(level)


def validate_seed(seed: object) -> int:
    """Return ``seed`` as an int if it is an integer in [0, :data:`SEED_LIMIT`).

    Raises:
        ValueError: otherwise.
    """
    import numbers

    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise ValueError(f"seed must be an integer in [0, 2**31), got {seed!r}")
    if not 0 <= int(seed) < SEED_LIMIT:
        raise ValueError(f"seed must be an integer in [0, 2**31), got {seed!r}")
    return int(seed)
