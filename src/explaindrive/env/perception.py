"""What the ego perceives each step: its leader, the next light, the next busy crossing, the
next yield line it must hold at, and the paper's 8-dim observation built from them.

The lights are read link by link from SUMO (``vehicle.getNextTLS``): the stop line and the
signal index of the link the ego will actually use, from the lane it is on, through its
connection to the next edge of its route, with that connection's ``linkIndex`` in the
programme. A joined cluster's several stop lines are each a link of their own.

A junction where the ego must let a foe with priority pass first (a minor road, a permissive
turn, a merge: :mod:`explaindrive.env.right_of_way`) puts a virtual leader at its stop line,
as a red light does; the observation keeps its 8 dimensions.

Each sensor is a small object that reads the running simulation and returns a value; none
writes episode state (the yield sensor remembers the ego's link into each junction it
approached, to read the foes while the ego passes it). :class:`Perception` combines them
into a :class:`Percept`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import traci.constants as tc
from numpy.typing import NDArray

from explaindrive.commands import Command
from explaindrive.env import state as S
from explaindrive.env.lane_split import SplitSensor, vehicle_length
from explaindrive.env.lights import AmberDecision
from explaindrive.env.right_of_way import NO_YIELD, YieldReading, YieldSensor
from explaindrive.env.way_ahead import WayAhead
from explaindrive.sim.crossing_lanes import CrossingLane, pedestrian_in_lane
from explaindrive.sim.pedestrians import KerbYield
from explaindrive.sim.route import RouteCrossing, RouteGeometry
from explaindrive.sim.scenario.files import EGO_ID

JUDGE_CROSSING_M = S.MAX_SPEED_MPS + 5.0  # [m] a crossing this close may be entered next step
_LOW: tuple[float, ...] = tuple(float(x) for x in S.STATE_LOW)
_HIGH: tuple[float, ...] = tuple(float(x) for x in S.STATE_HIGH)


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class Leader:
    """What the ego follows: a vehicle, or a zero-length virtual one at a stop line."""

    gap_m: float
    speed_mps: float
    length_m: float
    virtual: bool


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class LightReading:
    """The next signalled link of the ego's way within sensor range.

    Attributes:
        gap_m: from the ego's front to its stop line (sensor range: none).
        colour: its colour for the ego (green when none is in range).
        light_id: its traffic light id and link index (``None``: none in range).
    """

    gap_m: float = S.SENSOR_RANGE_M
    colour: S.LightState = S.LightState.GREEN
    light_id: tuple[str, int] | None = None


NO_LIGHT = LightReading()
"""The reading with no light in sensor range."""


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class CrossingReading:
    """The crossings ahead.

    Attributes:
        gap_m: to the nearest one a pedestrian is on or entering (sensor range: none).
        in_lane: crossing edge -> a pedestrian is in, or stepping into, the ego's lane there
            (for the crossings in range; judged only near enough to be entered next step).
    """

    gap_m: float
    in_lane: dict[str, bool]


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class Percept:
    """One step's perception.

    Attributes:
        obs: the raw observation (clipped to the state bounds).
        leader: the effective leader (real or virtual), ``None`` if none in range.
        real: the real leader, ``None`` if none in range.
        links: the signalled links on the ego's way (:func:`signal_links`).
        crossings: the crossings ahead.
        light_colour: the true colour of the next light (the observation may show a yellow
            the ego goes through as green, :meth:`AmberDecision.shown_colour`).
        yields: the yield lines where the ego must let a foe pass, and the conflict areas
            it may enter next (:class:`~explaindrive.env.right_of_way.YieldSensor`).
    """

    obs: NDArray[np.float32]
    leader: Leader | None
    real: Leader | None
    links: tuple[SignalLink, ...]
    crossings: CrossingReading
    light_colour: S.LightState = S.LightState.GREEN
    yields: YieldReading = NO_YIELD


class LeaderSensor:
    """The vehicle ahead in the ego's way within sensor range (bumper-to-bumper gap).

    SUMO's leader of the ego (``VAR_LEADER``, read after each step), so a vehicle that
    changes into the ego's lane ahead is the leader from the step it is in the lane, and
    one beside the ego is none (tests/env/test_cut_in.py); or, if nearer, a vehicle on the
    ego's lanes ahead that SUMO's leader leaves out
    (:class:`~explaindrive.env.way_ahead.WayAhead`, tests/env/test_way_ahead.py), or a
    vehicle in the other branch of a lane split whose back is still in the ego's way
    (:class:`~explaindrive.env.lane_split.SplitSensor`, tests/env/test_lane_split.py).

    Args:
        ego_min_gap_m: the ego's minGap, which SUMO subtracts from leader gaps [m].
        lengths: a cache of vehicle lengths by id, shared across episodes.
    """

    def __init__(self, ego_min_gap_m: float, lengths: dict[str, float]) -> None:
        self.ego_min_gap_m = ego_min_gap_m
        self._lengths = lengths
        self.splits = SplitSensor(lengths)
        self.ahead = WayAhead(lengths)

    def __call__(self, api: Any, ego: Any, next_links: Sequence[Any]) -> Leader | None:
        """The real leader from the ego's subscription results ``ego``: SUMO's, a vehicle on
        the ego's lanes ahead (:mod:`explaindrive.env.way_ahead`), or a vehicle in the other
        branch of a lane split that is still in the ego's way
        (:mod:`explaindrive.env.lane_split`), whichever is nearer (``next_links``: the ego's
        ``vehicle.getNextLinks`` this step)."""
        lead = ego.get(tc.VAR_LEADER)
        gap, lid = S.SENSOR_RANGE_M, ""
        if lead and lead[0]:
            gap, lid = float(lead[1]) + self.ego_min_gap_m, lead[0]
        lane = ego.get(tc.VAR_LANE_ID)
        if lane:
            pos = float(ego[tc.VAR_LANEPOSITION])
            ahead = self.ahead(api, lane, pos, next_links, within_m=gap)
            if ahead is not None:
                gap, lid = ahead
            split = self.splits(api, lane, pos, next_links)
            if split is not None and split[0] < gap:
                gap, lid = split
        if gap >= S.SENSOR_RANGE_M:
            return None
        length = vehicle_length(api, self._lengths, lid)
        return Leader(max(gap, 0.0), float(api.vehicle.getSpeed(lid)), length, False)


class SignalLink(NamedTuple):
    """A signalled link on the ego's way, as SUMO reads it from the lane the ego is on.

    The first is the link from the ego's lane (or from the lane SUMO keeps it on for its
    route) into the next edge of the route; then every later one to the route's end. A
    joined cluster (one programme for several nearby junctions) has several stop lines, so
    one ``tls_id`` can come several times, each with the index of its own link.

    Attributes:
        tls_id: the traffic light (programme) that controls the link.
        link_index: the link's index in that programme's state (its ``linkIndex``).
        gap_m: from the ego's front to the link's stop line [m].
        state: the link's signal this step (a character of SUMO's state string).
    """

    tls_id: str
    link_index: int
    gap_m: float
    state: str


def signal_links(api: Any) -> tuple[SignalLink, ...]:
    """The signalled links on the ego's way this step, nearest first."""
    return tuple(SignalLink(*link) for link in api.vehicle.getNextTLS(EGO_ID))


def light_ahead(links: tuple[SignalLink, ...]) -> LightReading:
    """The reading of the nearest of ``links`` (:func:`signal_links`) within sensor range."""
    if links and links[0].gap_m < S.SENSOR_RANGE_M:
        link = links[0]
        colour = S.LightState.from_sumo(link.state)
        return LightReading(link.gap_m, colour, (link.tls_id, link.link_index))
    return NO_LIGHT


def cluster_onward(
    links: tuple[SignalLink, ...],
) -> list[tuple[tuple[str, int], S.LightState, float]]:
    """The later stop lines within sensor range of the programme of the nearest of ``links``
    (a joined cluster's), as ``(light, colour, gap [m])``: a red or a yellow the ego stops
    for there is a virtual leader while the nearest line is green or gone through
    (:class:`~explaindrive.env.lights.AmberDecision`)."""
    if not links:
        return []
    tls_id = links[0].tls_id
    return [
        ((link.tls_id, link.link_index), S.LightState.from_sumo(link.state), link.gap_m)
        for link in links[1:]
        if link.tls_id == tls_id and link.gap_m < S.SENSOR_RANGE_M
    ]


def link_colour(api: Any, link: SignalLink) -> S.LightState:
    """The colour ``link`` shows now (read afresh: ``link.state`` is that of its step)."""
    states = api.trafficlight.getRedYellowGreenState(link.tls_id)
    return S.LightState.from_sumo(states[link.link_index])


class CrossingSensor:
    """Pedestrians on, or about to step onto, the crossings of the ego's route.

    Args:
        crossings: the route's crossings.
        lanes: crossing edge -> the ego lane's stretch on it.
    """

    def __init__(
        self, crossings: tuple[RouteCrossing, ...], lanes: dict[str, CrossingLane]
    ) -> None:
        self.crossings = crossings
        self.lanes = lanes

    @staticmethod
    def persons(api: Any, edge: str) -> tuple[str, ...]:
        """The pedestrians on ``edge`` this step (a subscribed crossing or walking area)."""
        res = api.edge.getSubscriptionResults(edge)
        return tuple(res.get(tc.LAST_STEP_PERSON_ID_LIST, ()))

    def in_lane(self, api: Any, crossing: RouteCrossing, persons: tuple[str, ...]) -> bool:
        """Whether one of ``persons`` is in, or stepping into, the ego's lane on ``crossing``."""
        lane = self.lanes[crossing.crossing_edge]
        return any(pedestrian_in_lane(api, lane, pid) for pid in persons)

    def occupied(
        self, api: Any, crossing: RouteCrossing, kerb: KerbYield, on_it: bool, judge: bool
    ) -> tuple[bool, bool]:
        """(busy, in_lane): a pedestrian is on the crossing or, at a zebra, about to
        step onto it; and whether one is in, or stepping into, the ego's lane on it
        (looked at only with ``judge``: the ego is close enough to cross the line next).

        At a signalized crossing pedestrians waiting on the kerb wait for their own
        green, and once the ego is on the crossing (``on_it``) those on the kerb wait for
        it, so then only pedestrians already on the crossing count. At a zebra, those
        waiting for the ego (``kerb``) do not.
        """
        on_crossing = self.persons(api, crossing.crossing_edge)
        if on_crossing:
            return True, judge and self.in_lane(api, crossing, on_crossing)
        if crossing.signalized or on_it:
            return False, False
        entering = tuple(
            pid
            for wa in crossing.walkingareas
            for pid in self.persons(api, wa)
            if api.person.getNextEdge(pid) == crossing.crossing_edge and not kerb.holds(pid)
        )
        return bool(entering), judge and bool(entering) and self.in_lane(api, crossing, entering)

    def __call__(self, api: Any, pos_m: float, kerb: KerbYield) -> CrossingReading:
        """The crossings ahead of route position ``pos_m``.

        A crossing counts from sensor range until the ego's front has left the junction: a
        car stopped on the crossing (e.g. by a STOP command) must not roll into pedestrians.
        """
        gap_m = S.SENSOR_RANGE_M
        in_lane: dict[str, bool] = {}
        for crossing in self.crossings:
            ahead = crossing.stop_line_m - pos_m
            if crossing.stop_line_m - crossing.end_m <= ahead < S.SENSOR_RANGE_M:
                busy, in_lane[crossing.crossing_edge] = self.occupied(
                    api, crossing, kerb, on_it=ahead < 0.0, judge=ahead < JUDGE_CROSSING_M
                )
                if busy:
                    gap_m = min(gap_m, max(ahead, 0.0))
        return CrossingReading(gap_m, in_lane)


def effective_leader(
    real: Leader | None,
    light_line: bool,
    light_gap_m: float,
    crossing_gap_m: float,
    yield_gap_m: float = S.SENSOR_RANGE_M,
) -> Leader | None:
    """The nearest of the real leader, the stop line of a light that is a virtual leader
    (``light_line``), a busy crossing in range and a yield line in range where the ego must
    let a foe pass."""
    leader = real
    if light_line and (leader is None or light_gap_m < leader.gap_m):
        leader = Leader(max(light_gap_m, 0.0), 0.0, 0.0, True)
    for gap_m in (crossing_gap_m, yield_gap_m):
        if gap_m < S.SENSOR_RANGE_M and (leader is None or gap_m < leader.gap_m):
            leader = Leader(gap_m, 0.0, 0.0, True)
    return leader


def observation(
    command: Command,
    speed_mps: float,
    posted_limit_mps: float,
    leader: Leader | None,
    light: LightReading,
    crossing_gap_m: float,
) -> NDArray[np.float32]:
    """The paper's 8-dim raw observation (:mod:`explaindrive.env.state`), clipped to its
    bounds."""
    rng = S.SENSOR_RANGE_M
    values = (
        float(command),
        speed_mps,
        posted_limit_mps,
        leader.gap_m if leader else rng,
        (speed_mps - leader.speed_mps) if leader else 0.0,
        light.gap_m,
        float(light.colour),
        crossing_gap_m,
    )
    # clipped in Python (the bounds are float32 values, so rounding afterwards gives the
    # same result as clipping the float32 array): cheaper than two numpy calls
    return np.array(
        [min(max(x, lo), hi) for x, lo, hi in zip(values, _LOW, _HIGH, strict=True)],
        dtype=np.float32,
    )


class Perception:
    """The ego's sensors on one network for one entry of the ego.

    Args:
        geometry: the route's geometry.
        crossing_lanes: crossing edge -> the ego lane's stretch on it.
        leaders: the leader sensor.
        ego_length_m: the ego's length [m] (how long it takes to clear a junction).
        unregulated: the ids of the route's ``unregulated`` junctions
            (:class:`~explaindrive.env.right_of_way.YieldSensor`).
    """

    def __init__(
        self,
        geometry: RouteGeometry,
        crossing_lanes: dict[str, CrossingLane],
        leaders: LeaderSensor,
        ego_length_m: float,
        unregulated: frozenset[str] = frozenset(),
    ) -> None:
        self.geometry = geometry
        self.leaders = leaders
        self.crossings = CrossingSensor(geometry.crossings, crossing_lanes)
        junctions = ((j.node_id, j.start_m, j.end_m) for j in geometry.junctions)
        self.yields = YieldSensor(junctions, ego_length_m, unregulated)

    def __call__(
        self,
        api: Any,
        ego: Any,
        pos_m: float,
        command: Command,
        amber: AmberDecision,
        kerb: KerbYield,
    ) -> Percept:
        """What the ego perceives at route position ``pos_m``.

        Args:
            api: the running simulation.
            ego: the ego's subscription results of the current step.
            pos_m: the ego's front along its route [m].
            command: the active command.
            amber: the decision at yellow (updated when a yellow is first seen).
            kerb: the pedestrians waiting for the ego at a zebra.
        """
        v = float(ego[tc.VAR_SPEED])
        next_links = api.vehicle.getNextLinks(EGO_ID)
        real = self.leaders(api, ego, next_links)
        links = signal_links(api)
        light = light_ahead(links)
        onward = cluster_onward(links)
        flags = amber.leaders([(light.light_id, light.colour, light.gap_m), *onward], v)
        at_line = flags[0]
        line_gap = light.gap_m if at_line else S.SENSOR_RANGE_M
        for (_light, _colour, gap_m), leads in zip(onward, flags[1:], strict=True):
            line_gap = min(line_gap, gap_m) if leads else line_gap
        true_colour = light.colour
        shown = amber.shown_colour(true_colour, at_line)
        if shown is not true_colour:
            light = dataclasses.replace(light, colour=shown)
        crossings = self.crossings(api, pos_m, kerb)
        limit = self.geometry.posted_limit(pos_m)
        yields = self.yields(api, pos_m, v, limit, next_links)
        leader = effective_leader(real, line_gap < S.SENSOR_RANGE_M, line_gap, crossings.gap_m,
                                  yields.leader_gap_m)  # fmt: skip
        obs = observation(command, v, limit, leader, light, crossings.gap_m)
        return Percept(obs, leader, real, links, crossings, true_colour, yields)
