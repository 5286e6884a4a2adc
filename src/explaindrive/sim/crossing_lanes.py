"""Where the ego's lane lies on each pedestrian crossing of its route, and whether a
pedestrian is in it or stepping into it.

A pedestrian-yield violation is a car crossing the stop line while a pedestrian is in, or
about to step into, the car's own lane; a pedestrian walking on the far side of a two-way
road is clear of it. The lane's stretch along the crossing is read from the network with
sumolib; pedestrians are located by their position, projected onto the crossing.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sumolib import geomhelper

from explaindrive.sim.route import read_net

BODY_HALF_WIDTH_M = 0.5  # [m] a pedestrian this close to the lane's edge is in it
ENTERING_HORIZON_S = 1.0  # [s] a pedestrian who reaches the lane within this is entering it


@dataclass(frozen=True, slots=True)
class CrossingLane:
    """The ego lane's stretch along one crossing.

    Attributes:
        shape: the crossing's centre line ``((x, y), ...)`` [m].
        lo_m, hi_m: the lane's edges as offsets along that line [m].
    """

    shape: tuple[tuple[float, float], ...]
    lo_m: float
    hi_m: float

    def offset_of(self, x: float, y: float) -> float:
        """A point's offset along the crossing's centre line [m]."""
        return float(geomhelper.polygonOffsetWithMinimumDistanceToPoint((x, y), self.shape))

    def direction(self) -> tuple[float, float]:
        """Unit vector from the crossing's first point to its last."""
        (x0, y0), (x1, y1) = self.shape[0], self.shape[-1]
        norm = math.hypot(x1 - x0, y1 - y0) or 1.0
        return (x1 - x0) / norm, (y1 - y0) / norm

    def occupied_by(self, offset_m: float, heading: float, speed_mps: float) -> bool:
        """Whether a pedestrian at ``offset_m`` walking with ``speed_mps`` along ``heading``
        (+1 towards the crossing's last point, -1 back, 0 standing) is in the lane or steps
        into it within :data:`ENTERING_HORIZON_S`."""
        lo, hi = self.lo_m - BODY_HALF_WIDTH_M, self.hi_m + BODY_HALF_WIDTH_M
        if lo <= offset_m <= hi:
            return True
        reach = max(speed_mps, 0.0) * ENTERING_HORIZON_S
        if offset_m < lo:
            return heading > 0 and offset_m + reach >= lo
        return heading < 0 and offset_m - reach <= hi


def crossing_lanes(
    net_file: str | Path, crossings: dict[str, str], net: Any | None = None
) -> dict[str, CrossingLane]:
    """The ego lane's stretch along each crossing.

    Args:
        net_file: the SUMO network.
        crossings: crossing edge id -> the route edge that approaches it (the ego drives on
            its first lane that allows passenger cars).
        net: ``net_file`` as :func:`~explaindrive.sim.route.read_net` read it, if the
            caller already has it.

    Raises:
        ValueError: if a crossing or edge is not in the network, or the edge has no lane
            for cars.
    """
    net = read_net(net_file) if net is None else net
    out: dict[str, CrossingLane] = {}
    for crossing_edge, edge_id in crossings.items():
        try:
            crossing = net.getEdge(crossing_edge).getLanes()[0]
            lanes = [ln for ln in net.getEdge(edge_id).getLanes() if ln.allows("passenger")]
        except KeyError as exc:
            raise ValueError(f"{exc.args[0]} is not in {net_file}") from None
        if not lanes:
            raise ValueError(f"edge {edge_id} in {net_file} has no lane for cars")
        lane = lanes[0]
        shape = tuple((float(x), float(y)) for x, y, *_ in crossing.getShape())
        centre = geomhelper.polygonOffsetWithMinimumDistanceToPoint(lane.getShape()[-1], shape)
        half = float(lane.getWidth()) / 2.0
        length = sum(math.dist(a, b) for a, b in itertools.pairwise(shape))
        out[crossing_edge] = CrossingLane(
            shape, max(0.0, centre - half), min(length, centre + half)
        )
    return out


def pedestrian_in_lane(api: Any, lane: CrossingLane, person_id: str) -> bool:
    """Whether a person on (or at the kerb of) the crossing is in or entering the lane."""
    person = api.person
    x, y = person.getPosition(person_id)
    offset = lane.offset_of(float(x), float(y))
    angle = math.radians(float(person.getAngle(person_id)))  # 0 = north, clockwise
    hx, hy = math.sin(angle), math.cos(angle)
    dx, dy = lane.direction()
    along = hx * dx + hy * dy
    heading = 0.0 if abs(along) < 0.3 else math.copysign(1.0, along)
    return lane.occupied_by(offset, heading, float(person.getSpeed(person_id)))
