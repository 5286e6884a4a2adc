"""The ego's route position, anchored to the edge it is on.

The route's geometry (:mod:`explaindrive.sim.route`) lays the route out along one reference
lane per edge (its leftmost car lane) and the internal lanes of the connections from it. The
ego drives other lanes too, and on a real city's curved, multi-lane roads their lengths
differ from the reference's by a few per cent. Counted as distance driven, the error adds up
along the route: after 2.3 km of a real network the ego's route position was 20 m short of
where it stood, so the stop lines, yield lines and crossings it read were 20 m off.

:class:`RouteOdometer` anchors the position to the edge the ego is on: on a normal edge its
share of the lane it drives, laid onto the edge's stretch of the route (exact at the edge's
start and at its stop line); inside a junction the distance driven since, up to the start of
the next edge. The position never decreases.
"""

from __future__ import annotations

from typing import Any

from explaindrive.env.lane_split import read_once
from explaindrive.sim.route import RouteGeometry


class RouteOdometer:
    """The ego's route position through one episode (module docstring).

    Args:
        geometry: the route's geometry.
        start_pos_m: the ego's route position at entry [m].
    """

    def __init__(self, geometry: RouteGeometry, start_pos_m: float) -> None:
        self.geometry = geometry
        self.pos_m = start_pos_m
        self._lane_lengths: dict[str, float] = {}
        self._index = 0  # the route edge the ego was last on
        self._driven_m = 0.0

    def edge_index(self, edge: str) -> int | None:
        """The index of ``edge`` in the route, from the edge the ego was last on onward
        (``None``: not on the rest of the route)."""
        edges = self.geometry.edges
        for i in range(self._index, len(edges)):
            if edges[i] == edge:
                return i
        return None

    def __call__(self, api: Any, lane: str, lane_pos_m: float, driven_m: float) -> float:
        """The route position after a step that left the ego at ``lane_pos_m`` on ``lane``
        (``driven_m``: its distance driven since entry, SUMO's ``VAR_DISTANCE``)."""
        step_m, self._driven_m = driven_m - self._driven_m, driven_m
        geometry = self.geometry
        i = None if lane.startswith(":") else self.edge_index(lane.rsplit("_", 1)[0])
        if i is None:  # inside a junction (or off the route): as driven, to the next edge
            pos = self.pos_m + step_m
            if self._index + 1 < len(geometry.edges):
                pos = min(pos, geometry.edge_start_m[self._index + 1])
        else:
            self._index = i
            start = geometry.edge_start_m[i]
            end = geometry.edge_end_m(i)
            lane_m = read_once(self._lane_lengths, lane, api.lane.getLength)
            pos = start + (end - start) * min(lane_pos_m / lane_m, 1.0) if lane_m > 0 else start
        self.pos_m = max(self.pos_m, pos)
        return self.pos_m
