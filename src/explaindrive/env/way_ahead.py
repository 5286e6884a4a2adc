"""The vehicles on the ego's own lanes ahead, read lane by lane.

SUMO's leader of the ego (``VAR_LEADER``) walks the ego's best lanes, and on a real city's
network it can leave out a vehicle that stands on them: where short edges and internal lanes
follow one another through a cluster of junctions (an edge 0.9 m long between two junctions,
a minor road merging into a short link road), a car that has just merged onto the ego's way
and stands on the next junction's internal lane, 20 m ahead, is reported only when the ego
is 12 m from it and closing at 9.5 m/s, too late to stop from 12 m/s.

:class:`WayAhead` reads the lanes themselves: the ego's lane, the internal lanes of each link
of its route ahead (``vehicle.getNextLinks``: the lane after the link and the link's via lane,
with the second part of a via lane that leads to an internal junction) and the lanes after
them, to sensor range, and the vehicles on each (``lane.getLastStepVehicleIDs``). The
nearest back ahead of the ego's front is its leader, bumper to bumper. Lane lengths and
the internal chains are read from SUMO once and kept.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

from explaindrive.env import state as S
from explaindrive.env.lane_split import read_once, vehicle_length
from explaindrive.sim.scenario.files import EGO_ID


class WayAhead:
    """The nearest vehicle on the ego's lanes ahead (module docstring).

    Args:
        lengths: a cache of vehicle lengths by id, shared with the leader sensor.
        range_m: how far ahead to read [m] (the sensor range).
    """

    def __init__(self, lengths: dict[str, float], range_m: float = S.SENSOR_RANGE_M) -> None:
        self._lengths = lengths
        self.range_m = range_m
        self._lane_lengths: dict[str, float] = {}
        self._chains: dict[str, tuple[str, ...]] = {}  # internal lane -> it and its onward part

    def _length(self, api: Any, lane: str) -> float:
        return read_once(self._lane_lengths, lane, api.lane.getLength)

    def chain(self, api: Any, via: str) -> tuple[str, ...]:
        """The internal lanes a link through ``via`` drives: ``via``, then the second part
        where ``via`` leads to an internal junction (read once, then kept)."""
        kept = self._chains.get(via)
        if kept is None:
            lanes = [via]
            onward = api.lane.getLinks(via)
            if len(onward) == 1 and str(onward[0][4]).startswith(":"):
                lanes.append(str(onward[0][4]))
            kept = self._chains[via] = tuple(lanes)
        return kept

    def lanes(
        self, api: Any, lane: str, lane_pos_m: float, next_links: Sequence[Any]
    ) -> Iterator[tuple[str, float]]:
        """The ego's lanes from ``lane`` on, each with the distance from the ego's front to
        its start [m] (negative for the ego's own lane), to sensor range."""
        start = -lane_pos_m
        yield lane, start
        start += self._length(api, lane)
        ahead: list[str] = []
        if lane.startswith(":"):  # inside a junction: the rest of its link first
            onward = api.lane.getLinks(lane)
            if len(onward) == 1:
                via = str(onward[0][4])
                ahead += [via] if via.startswith(":") else []
                ahead.append(str(onward[0][0]))
        for link in next_links:
            via = str(link[4])
            ahead += self.chain(api, via) if via.startswith(":") else ()
            ahead.append(str(link[0]))
        for on in ahead:
            if start >= self.range_m:
                return
            yield on, start
            start += self._length(api, on)

    def __call__(
        self,
        api: Any,
        lane: str,
        lane_pos_m: float,
        next_links: Sequence[Any],
        within_m: float | None = None,
    ) -> tuple[float, str] | None:
        """The nearest vehicle on the ego's lanes ahead: the gap from the ego's front to its
        back [m] and its id (``None``: none within sensor range, or within ``within_m``).

        Args:
            api: the running simulation.
            lane: the ego's lane.
            lane_pos_m: the ego's front along it.
            next_links: the ego's links ahead this step (``vehicle.getNextLinks``).
            within_m: read only this far [m] (a leader already known at that gap: the lanes
                beyond it are not read).
        """
        bound = self.range_m if within_m is None else min(within_m, self.range_m)
        nearest: tuple[float, str] | None = None
        for on, start in self.lanes(api, lane, lane_pos_m, next_links):
            if start >= (bound if nearest is None else nearest[0]):
                break
            for vid in api.lane.getLastStepVehicleIDs(on):
                if vid == EGO_ID:
                    continue
                front = float(api.vehicle.getLanePosition(vid))
                if start + front <= 0.0:  # beside or behind the ego's front
                    continue
                gap = start + front - vehicle_length(api, self._lengths, vid)
                if gap < bound and (nearest is None or gap < nearest[0]):
                    nearest = (gap, vid)
        return nearest
