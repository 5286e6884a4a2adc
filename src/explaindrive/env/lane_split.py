"""A vehicle in the other branch of a lane split, still in the ego's way.

Where one lane forks into two (a turn lane opening beside the through lane, ``turn_lane_m`` in
the scenario family), the junction has one internal lane per branch; both start at the same
stop line, side by side, and part over a few metres. A vehicle that has just taken the other
branch and stands there (its branch is queued up) still blocks the ego's, but SUMO's leader
of the ego (``VAR_LEADER``) follows the ego's own lanes only and leaves it out: the ego would
drive into it.

:class:`SplitSensor` reads such a vehicle as a leader: one on a sibling internal lane (another
link out of the lane the ego's link leaves from) whose back is still within the stretch where
the two centre lines are closer than :data:`SIDE_BY_SIDE_M` (:func:`shared_stretch_m`, read
once per pair from the lane shapes), ahead of the ego's front.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

from explaindrive.env import state as S

SIDE_BY_SIDE_M = 2.0
"""[m] Two centre lines closer than this leave no room for two cars side by side (1.8 m wide
each, SUMO's default passenger car, with 0.2 m to spare)."""
_SAMPLE_M = 0.25  # [m] spacing of the points read along a lane shape


def _point_to_segment(
    p: tuple[float, float], a: tuple[float, float], b: tuple[float, float]
) -> float:
    (px, py), (ax, ay), (bx, by) = p, a, b
    dx, dy = bx - ax, by - ay
    seg2 = dx * dx + dy * dy
    t = 0.0 if seg2 == 0.0 else max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / seg2))
    return math.hypot(px - (ax + t * dx), py - (ay + t * dy))


def shared_stretch_m(
    ours: Sequence[tuple[float, float]], theirs: Sequence[tuple[float, float]]
) -> float:
    """[m] How far along ``theirs`` (a polyline) its points stay within
    :data:`SIDE_BY_SIDE_M` of the polyline ``ours`` (``0``: they start apart; the whole
    length: they never part)."""
    along = 0.0
    for a, b in itertools.pairwise(theirs):
        seg = math.hypot(b[0] - a[0], b[1] - a[1])
        steps = max(1, math.ceil(seg / _SAMPLE_M))
        for i in range(steps + 1):
            f = i / steps
            p = (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]))
            near = min(_point_to_segment(p, c, d) for c, d in itertools.pairwise(ours))
            if near >= SIDE_BY_SIDE_M:
                return along + f * seg
        along += seg
    return along


def read_once(cache: dict[str, float], key: str, read: Callable[[str], Any]) -> float:
    """``read(key)`` as a float, read once and kept in ``cache`` (SUMO's fixed lengths)."""
    value = cache.get(key)
    if value is None:
        value = cache[key] = float(read(key))
    return value


def vehicle_length(api: Any, lengths: dict[str, float], vid: str) -> float:
    """[m] Vehicle ``vid``'s length, read from SUMO once and kept in ``lengths``."""
    return read_once(lengths, vid, api.vehicle.getLength)


class Branch(NamedTuple):
    """The other branches of a split beside the ego's internal lane.

    Attributes:
        approach: the lane the ego's link leaves from.
        siblings: ``(internal lane, its length [m], the lane after it, how far along it it
            shares the ego's way [m])`` of each other link out of ``approach`` that is not
            apart from the start.
    """

    approach: str
    siblings: tuple[tuple[str, float, str, float], ...]


class SplitSensor:
    """The nearest vehicle in another branch of a lane split that is still in the ego's way
    (module docstring).

    Args:
        lengths: a cache of vehicle lengths by id, shared with the leader sensor.
    """

    def __init__(self, lengths: dict[str, float]) -> None:
        self._lengths = lengths
        self._branches: dict[str, Branch] = {}  # the ego's internal lane -> its branch
        self._lane_lengths: dict[str, float] = {}

    def branch(self, api: Any, approach: str, via: str) -> Branch:
        """The :class:`Branch` of the ego's internal lane ``via`` out of ``approach`` (read
        once, then kept)."""
        kept = self._branches.get(via)
        if kept is None:
            ours = api.lane.getShape(via)
            vias = [str(link[4]) for link in api.lane.getLinks(approach)]
            siblings = []
            for other in vias if via in vias else ():  # else: not the ego's link out of it
                if other.startswith(":") and other != via:
                    shared = shared_stretch_m(ours, api.lane.getShape(other))
                    onward = api.lane.getLinks(other)
                    if shared > 0.0:
                        length = float(api.lane.getLength(other))
                        siblings.append(
                            (other, length, str(onward[0][0]) if onward else "", shared)
                        )
            kept = self._branches[via] = Branch(approach, tuple(siblings))
        return kept

    def __call__(
        self, api: Any, lane: str, lane_pos_m: float, next_links: Sequence[Any]
    ) -> tuple[float, str] | None:
        """The nearest vehicle in another branch that is still in the ego's way: the gap from
        the ego's front to its back [m] and its id (``None``: none within sensor range).

        Args:
            api: the running simulation.
            lane: the ego's lane.
            lane_pos_m: the ego's front along it.
            next_links: the ego's links ahead this step (``vehicle.getNextLinks``).
        """
        if lane in self._branches:  # on its own internal lane of a split
            branch, to_start = self._branches[lane], -lane_pos_m
        elif lane.startswith(":"):
            return None
        else:
            to_start = read_once(self._lane_lengths, lane, api.lane.getLength) - lane_pos_m
            if to_start >= S.SENSOR_RANGE_M or not next_links:
                return None
            via = str(next_links[0][4])
            if not via.startswith(":"):
                return None
            branch = self.branch(api, lane, via)
        nearest: tuple[float, str] | None = None
        for sibling, length_m, onward, shared_m in branch.siblings:
            for vid, back in self._backs(api, branch, sibling, length_m, onward):
                gap = to_start + back
                if back < shared_m and gap > 0.0 and (nearest is None or gap < nearest[0]):
                    nearest = (gap, vid)
        return nearest

    def _backs(
        self, api: Any, branch: Branch, lane: str, length_m: float, onward: str
    ) -> list[tuple[str, float]]:
        """The vehicles whose back is on ``lane``, a branch out of ``branch.approach`` (or
        before it), with where it is along ``lane`` [m]: those on it, and those on ``onward``
        that came through it (from the approach's edge) and whose back has not left it."""
        backs = []
        for on, offset in ((lane, 0.0), (onward, length_m)):
            for vid in api.lane.getLastStepVehicleIDs(on) if on else ():
                if on == onward and not self._came_from(api, vid, branch.approach):
                    continue
                length = vehicle_length(api, self._lengths, vid)
                back = offset + float(api.vehicle.getLanePosition(vid)) - length
                if back < length_m:
                    backs.append((vid, back))
        return backs

    @staticmethod
    def _came_from(api: Any, vid: str, approach: str) -> bool:
        """Whether vehicle ``vid``'s previous edge on its route is ``approach``'s edge."""
        index = int(api.vehicle.getRouteIndex(vid))
        route = api.vehicle.getRoute(vid)
        return index > 0 and route[index - 1] == api.lane.getEdgeID(approach)
