"""Right of way: where the ego must yield, and when its yield line is a virtual leader.

SUMO gives every link of a junction a state (a character of ``linkState`` or of the light's
programme). An upper-case state has priority (``G`` green major, ``M`` major road of a
priority junction, ``O`` a light switched off); the open lower-case ones
(:data:`YIELD_STATES`) must yield to the foes that have it: ``g`` a permissive turn at a
light (a left turn across oncoming traffic on a shared green), ``m`` a minor road at a
priority junction, ``s`` a stop sign, ``w`` an all-way stop, ``=`` right before left, ``o``
a blinking light switched off; ``Z`` (a zipper merge) yields too. Red, red-yellow and
yellow (``r``, ``u``, ``y``) are the light's to judge (:mod:`explaindrive.env.lights`). SUMO's own
drivers enter such a link only when no foe with priority will reach the conflict within
their time gap (``MSLink::opened``).

The ego perceives the same: ``vehicle.getJunctionFoes`` lists, for the links of its route
ahead, each foe approaching a conflict with the ego's way, the distances of both to the
conflict area and to its end, and whether the ego's link must respond to the foe's
(``egoResponse``, read from the junction's logic). :func:`must_yield` is the rule: the ego
yields to a foe when its own link lacks priority, the foe's link is not red, the foe has
not left the conflict and will not have left it (at its speed) before the ego reaches it,
with :data:`YIELD_MARGIN_S` to spare, and it will reach it before the ego has left it plus
that margin. The ego's clearing time is what its hardest acceleration
(+3 m/s a step, up to the posted limit) needs to bring its back past the conflict; the
foe's arrival is the earliest its own acceleration allows (a standing foe counts: it may
start).

Where the rule holds, the junction's stop line (its yield line) is a zero-length virtual
leader standing there, exactly as a red light's stop line is
(:func:`~explaindrive.env.perception.effective_leader`): the 8-dim observation keeps its
meaning (``d_lead`` is the gap to the line, ``dv`` the ego's speed), and the safety mask
(:mod:`explaindrive.env.safety`) and the run-time shield (:mod:`explaindrive.agent.shield`),
which read the leader from the observation, hold the ego before the line as they would
before a standing car. A line the ego can no longer stop before even braking hardest
(:func:`~explaindrive.env.actions.can_stop_before`) is not a leader: the ego is committed,
and braking would only leave it in the conflict (the yellow light's dilemma zone, in
:mod:`explaindrive.env.lights`). A line behind the ego's front (it is inside the junction)
is none either.

A turn across oncoming traffic (a permissive ``g`` at a light, or any yielding link whose via
lane leads to an internal junction) is where SUMO resolves the conflict at the internal
junction, where its own drivers wait inside the junction: the approach link's foes, and so
``getJunctionFoes``, leave the oncoming lanes out. The sensor reads them from the network
(:func:`turn_geometry`, once per via lane): ``lane.getFoes`` of the link out of the ego's via
lane gives the incoming lanes with right of way there, and of their links those whose via lane
is among the internal foes of the ego's way (``lane.getInternalFoes``) and whose centre line
crosses the ego's (:func:`crossing_offsets`) are its foes. The vehicles on such an incoming
lane bound for that via lane (a foe at red or red-yellow, or at yellow and able to stop, is
left out: :func:`stops_at_signal`), and those on the via lane, are foes with priority
(:func:`turn_foe`), their conflict area :data:`CONFLICT_HALF_M` either side of where the
centre lines cross, along each way. The rule then holds the ego where SUMO's own drivers
wait, inside the junction: at the internal junction, or short of the conflict area if that
comes first (:meth:`YieldSensor.wait_gap`). So when the phase ends and the oncoming stream
stops at its red, the ego clears the junction, as they do; held at the stop line it could
wait through every phase of a saturated stream. The judge reads the area (for this one it
lets the ego, which drives on from a wait, accelerate out of it at 2.6 m/s², SUMO's
default). Vehicles on the lanes before a foe's incoming lane are not seen.

The judge of yield violations (:func:`enters_in_front`) reads the conflict area itself, as
traffic-safety practice does with the post-encroachment time: the ego breaks the right of
way when its front enters a conflict area during a step (the area's start, seen before the
step, lies within the step's travel) while a foe with priority (``egoResponse``, its link not
red) has not left the area and will reach it before the ego's back has left it plus SUMO's
own gap, :data:`YIELD_JUDGE_GAP_S`. Both times are at the speeds they drive (no hardest
acceleration here): the ego's over the step, with the acceleration it drove the step with
held while it clears (up to SUMO's default 2.6 m/s²: a car driving off from a wait at the
line clears as it accelerates), the foe's as read before it; a standing foe
that has not entered never arrives, one standing inside never leaves. SUMO's drivers may
cross the stop line and wait short of the conflict (inside the junction for a left turn)
until their own gap rule lets them in, which is no violation: only the entry into the area
is judged, and only at a link that yields.

``getJunctionFoes`` is asked only when a yielding link lies within sensor range or the ego
is inside a junction it entered by one, and only as far as the last such link: SUMO 1.28's
libsumo crashes (a segmentation fault) when its look-ahead reaches an ``unregulated``
junction (one without junction logic, such as the centre of netgenerate's spider networks),
so the look-ahead also stops before the first one on the route; a yielding link beyond it
is read once the ego has passed it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from explaindrive.env import state as S
from explaindrive.env.actions import SPEED_CHANGES_MPS, STEP_LENGTH_S, can_stop_before
from explaindrive.sim.scenario.files import EGO_ID

FOE_MOVING_MPS = 0.1
"""[m/s] A foe slower than this is standing: it does not leave the conflict on its own."""
YIELD_JUDGE_GAP_S = 1.0
"""[s] The gap a yield violation breaks: a foe with priority reaching the conflict area less
than this after the ego's back has left it. SUMO's default ``jmTimegapMinor``, the time its
own drivers keep ahead of a prioritised vehicle, so SUMO's drivers are not flagged for what
they are built to do; the ego perceives with :data:`YIELD_MARGIN_S`."""
YIELD_MARGIN_S = 2.0
"""[s] A foe with priority must reach the conflict at least this long after the ego has left
it: SUMO's default ``jmTimegapMinor`` (1 s), the gap its Krauss drivers keep ahead of a
prioritised vehicle, plus 1 s because the policy may not accelerate as hard as the clearing
time assumes."""
MAX_ACCEL_MPS = max(SPEED_CHANGES_MPS)  # [m/s per step] the ego's hardest acceleration
FOE_ACCEL_MPS2 = 2.6  # [m/s^2] a foe's acceleration when SUMO gives none (its default)
YIELD_STATES = frozenset("gmsw=oZ")  # the ego's link states that yield to foes with priority
NO_SIGNAL_STATES = frozenset("rRu")  # a foe at red or red-yellow does not enter
CONFLICT_HALF_M = 2.5
"""[m] A turn's conflict area with a foe reaches this far either side of where their centre
lines cross: half a 3.2 m lane and half a 1.8 m car, and a little."""
_CLEAR_STEPS_MAX = 60  # steps after which a clearing time is taken as never


class JunctionFoe(NamedTuple):
    """A foe of ``vehicle.getJunctionFoes``: one vehicle approaching a conflict with the
    ego's way (distances along each one's way, negative once passed) [m]."""

    foe_id: str
    ego_dist_m: float  # the ego's front to the conflict area
    foe_dist_m: float  # the foe's front to the conflict area
    ego_exit_m: float  # the ego's front to the end of the conflict area
    foe_exit_m: float  # the foe's front to the end of the conflict area
    ego_lane: str  # the ego's internal lane through the conflict
    foe_lane: str  # the foe's internal lane through the conflict
    ego_responds: bool  # the ego's link must yield to the foe's (junction logic)
    foe_responds: bool  # the foe's link must yield to the ego's
    turning: bool = False  # a foe at the internal junction of the ego's turn (turn_foe)


@dataclass(frozen=True, slots=True)
class FoeMotion:
    """What the rule needs of a foe besides its conflict distances.

    Attributes:
        speed_mps: its speed.
        accel_mps2: its greatest acceleration.
        max_speed_mps: the fastest it drives there (its lane's limit times its speed factor).
        length_m: its length.
        link_state: the state of its link into the junction (``""`` once inside).
    """

    speed_mps: float
    accel_mps2: float
    max_speed_mps: float
    length_m: float
    link_state: str = ""


def link_yields(state: str) -> bool:
    """Whether a link in ``state`` (a SUMO link-state character) is open but must yield to
    foes with priority (:data:`YIELD_STATES`)."""
    return state in YIELD_STATES


def junction_of(internal_lane: str) -> str:
    """The junction id of an internal lane id (``:<junction>_<link>_<lane>``)."""
    return internal_lane[1:].rsplit("_", 2)[0] if internal_lane.startswith(":") else ""


def clear_time_s(distance_m: float, speed_mps: float, limit_mps: float) -> float:
    """[s] Steps for the ego's front to cover ``distance_m`` accelerating hardest
    (+:data:`MAX_ACCEL_MPS` a step, at most ``limit_mps``); SUMO moves a car by its new
    speed each step. ``inf`` beyond :data:`_CLEAR_STEPS_MAX` steps."""
    if distance_m <= 0.0:
        return 0.0
    v, covered = max(speed_mps, 0.0), 0.0
    for step in range(1, _CLEAR_STEPS_MAX + 1):
        v = max(min(v + MAX_ACCEL_MPS, limit_mps), 0.0)
        covered += v * STEP_LENGTH_S
        if covered >= distance_m:
            return step * STEP_LENGTH_S
    return math.inf


def arrival_time_s(
    distance_m: float, speed_mps: float, accel_mps2: float, max_speed_mps: float
) -> float:
    """[s] The earliest a foe at ``speed_mps`` covers ``distance_m``: accelerating at
    ``accel_mps2`` up to ``max_speed_mps`` (or its speed, if faster), then keeping it."""
    if distance_m <= 0.0:
        return 0.0
    v0, top = max(speed_mps, 0.0), max(speed_mps, max_speed_mps)
    if accel_mps2 <= 0.0 or v0 >= top:
        return distance_m / v0 if v0 > 0.0 else math.inf
    t_top = (top - v0) / accel_mps2
    d_top = v0 * t_top + 0.5 * accel_mps2 * t_top * t_top
    if distance_m <= d_top:
        return (-v0 + math.sqrt(v0 * v0 + 2.0 * accel_mps2 * distance_m)) / accel_mps2
    return t_top + (distance_m - d_top) / top


def must_yield(
    ego_link_state: str,
    foe: JunctionFoe,
    motion: FoeMotion,
    ego_speed_mps: float,
    ego_limit_mps: float,
    ego_length_m: float,
) -> bool:
    """The rule (module docstring): whether the ego must let ``foe`` pass before it enters,
    with :data:`YIELD_MARGIN_S` to spare.

    Args:
        ego_link_state: the state of the ego's link into the junction.
        foe: the foe and the conflict.
        motion: the foe's speed, acceleration, top speed, length and link state.
        ego_speed_mps: the ego's speed.
        ego_limit_mps: the ego's posted limit (its top speed through the junction).
        ego_length_m: the ego's length.
    """
    if not link_yields(ego_link_state) or not foe.ego_responds:
        return False
    if motion.link_state in NO_SIGNAL_STATES:
        return False
    if foe.foe_exit_m + motion.length_m <= 0.0:  # its back has left the conflict
        return False
    ego_arrives = clear_time_s(foe.ego_dist_m, ego_speed_mps, ego_limit_mps)
    _arrives, foe_leaves = foe_window_s(foe, motion)
    if foe_leaves + YIELD_MARGIN_S <= ego_arrives:  # it will be gone before the ego comes
        return False
    ego_clear = clear_time_s(foe.ego_exit_m + ego_length_m, ego_speed_mps, ego_limit_mps)
    foe_arrives = arrival_time_s(
        foe.foe_dist_m, motion.speed_mps, motion.accel_mps2, motion.max_speed_mps
    )
    return foe_arrives < ego_clear + YIELD_MARGIN_S


def foe_window_s(foe: JunctionFoe, motion: FoeMotion) -> tuple[float, float]:
    """[s] When ``foe``, keeping its speed, reaches the conflict area and when its back has
    left it (``0`` for what is behind it; a standing foe, slower than
    :data:`FOE_MOVING_MPS`, never reaches it and never leaves it)."""

    def at_speed(distance_m: float) -> float:
        if distance_m <= 0.0:
            return 0.0
        return distance_m / motion.speed_mps if motion.speed_mps > FOE_MOVING_MPS else math.inf

    return at_speed(foe.foe_dist_m), at_speed(foe.foe_exit_m + motion.length_m)


def enters_in_front(
    foe: JunctionFoe,
    motion: FoeMotion,
    travelled_m: float,
    ego_length_m: float,
    ego_accel_mps2: float = 0.0,
) -> bool:
    """The judge (module docstring): whether the ego, whose front travels ``travelled_m``
    during a step that starts with ``foe`` as read, enters their conflict area in front of a
    foe with priority over its link.

    The ego drives the step at ``travelled_m`` per :data:`STEP_LENGTH_S` (SUMO moves a car
    by its new speed) and clears the area at that speed, or, if it accelerated during the
    step, with that acceleration held (at most :data:`FOE_ACCEL_MPS2`); the times count
    from the step's start.

    Args:
        foe: the foe and the conflict, read before the step.
        motion: the foe's speed, length and link state, read before the step.
        travelled_m: how far the ego's front moved during the step.
        ego_length_m: the ego's length.
        ego_accel_mps2: the ego's acceleration during the step (its speed's rise over it).
    """
    if not 0.0 < foe.ego_dist_m <= travelled_m:  # no entry this step
        return False
    if not foe.ego_responds or motion.link_state in NO_SIGNAL_STATES:
        return False
    ego_speed_mps = travelled_m / STEP_LENGTH_S
    ego_enters = foe.ego_dist_m / ego_speed_mps
    accel = min(max(ego_accel_mps2, 0.0), FOE_ACCEL_MPS2)
    if foe.turning:  # it drives on from its wait at the internal junction: accelerating
        accel = FOE_ACCEL_MPS2
    ego_leaves = arrival_time_s(foe.ego_exit_m + ego_length_m, ego_speed_mps, accel, math.inf)
    foe_arrives, foe_leaves = foe_window_s(foe, motion)
    return foe_leaves > ego_enters and foe_arrives < ego_leaves + YIELD_JUDGE_GAP_S


def stops_at_signal(api: Any, foe_id: str, state: str, to_line_m: float) -> bool:
    """Whether a foe ``to_line_m`` before a link in ``state`` will not enter: the link is
    red or red-yellow (:data:`NO_SIGNAL_STATES`), or yellow and the foe can still stop
    before it braking at its own deceleration, as SUMO's drivers then do."""
    if state in NO_SIGNAL_STATES:
        return True
    if state not in "yY":
        return False
    speed = float(api.vehicle.getSpeed(foe_id))
    return speed * speed / (2.0 * float(api.vehicle.getDecel(foe_id))) <= to_line_m


class TurnGeometry(NamedTuple):
    """A link whose via lane leads to an internal junction, where a turning car waits for
    the foes SUMO resolves there (module docstring).

    Attributes:
        via_m: [m] the length of the ego's via lane, from the stop line to the internal
            junction.
        inner_lane: the internal lane after the internal junction.
        foes: ``(incoming lane, its via lane crossing the ego's way, where their centre
            lines cross [m] along that via lane and along the ego's way from its stop line)``
            of each link with right of way over the ego's at the internal junction.
    """

    via_m: float
    inner_lane: str
    foes: tuple[tuple[str, str, float, float], ...]


def crossing_offsets(
    ours: Sequence[tuple[float, float]], theirs: Sequence[tuple[float, float]]
) -> tuple[float, float] | None:
    """[m] Where two polylines first cross (or touch), as the distance along each from its
    start (the first crossing along ``ours``; ``None``: they do not meet)."""
    along_ours = 0.0
    for (ax, ay), (bx, by) in itertools.pairwise(ours):
        along_theirs, seg = 0.0, math.hypot(bx - ax, by - ay)
        for (cx, cy), (dx, dy) in itertools.pairwise(theirs):
            other = math.hypot(dx - cx, dy - cy)
            det = (bx - ax) * (dy - cy) - (by - ay) * (dx - cx)
            if det != 0.0:
                t = ((cx - ax) * (dy - cy) - (cy - ay) * (dx - cx)) / det
                u = ((cx - ax) * (by - ay) - (cy - ay) * (bx - ax)) / det
                if -1e-9 <= t <= 1.0 + 1e-9 and -1e-9 <= u <= 1.0 + 1e-9:
                    return along_ours + t * seg, along_theirs + u * other
            along_theirs += other
        along_ours += seg
    return None


def turn_geometry(api: Any, via: str) -> TurnGeometry | None:
    """The :class:`TurnGeometry` of the ego's via lane ``via``, read from the network
    (``None``: its link leads to no internal junction)."""
    onward = [link for link in api.lane.getLinks(via) if str(link[4]).startswith(":")]
    if not onward:
        return None
    next_lane, inner = str(onward[0][0]), str(onward[0][4])
    via_m = float(api.lane.getLength(via))
    path = [*api.lane.getShape(via), *api.lane.getShape(inner)]
    crossing = set(api.lane.getInternalFoes(via)) | set(api.lane.getInternalFoes(inner))
    foes = []
    for incoming in sorted(set(api.lane.getFoes(via, next_lane))):
        if incoming.startswith(":"):  # a walking area: pedestrians are not judged here
            continue
        for link in api.lane.getLinks(incoming):
            if link[4] in crossing:
                met = crossing_offsets(path, api.lane.getShape(link[4]))
                if met is not None:
                    foes.append((incoming, str(link[4]), met[1], met[0]))
    return TurnGeometry(via_m, inner, tuple(foes))


def turn_foe(
    foe_id: str,
    foe_via: str,
    foe_at_m: float,
    ego_at_m: float,
    foe_to_entry_m: float,
    ego_to_line_m: float,
    inner_lane: str,
) -> JunctionFoe:
    """A foe at a turn's internal junction as a :class:`JunctionFoe`: the conflict area is
    :data:`CONFLICT_HALF_M` either side of where the two centre lines cross.

    Args:
        foe_id: the foe.
        foe_via: its via lane through the junction.
        foe_at_m: [m] where the centre lines cross, along the foe's via lane.
        ego_at_m: [m] where they cross, along the ego's way from its stop line.
        foe_to_entry_m: [m] from the foe's front to the start of its via lane (negative
            inside).
        ego_to_line_m: [m] from the ego's front to its stop line (negative past it).
        inner_lane: the ego's internal lane after its internal junction.
    """
    ego_at, foe_at = ego_to_line_m + ego_at_m, foe_to_entry_m + foe_at_m
    return JunctionFoe(
        foe_id, ego_at - CONFLICT_HALF_M, foe_at - CONFLICT_HALF_M, ego_at + CONFLICT_HALF_M,
        foe_at + CONFLICT_HALF_M, inner_lane, foe_via, True, False, True,
    )  # fmt: skip


class Conflict(NamedTuple):
    """A conflict area the ego may enter in the coming step, and a foe with priority over its
    link there (read before the step, for :func:`enters_in_front`)."""

    foe: JunctionFoe
    motion: FoeMotion


class YieldReading(NamedTuple):
    """The yield lines and conflict areas ahead this step.

    Attributes:
        leader_gap_m: [m] from the ego's front to the nearest yield line where the ego must
            yield and can still stop: a virtual leader (sensor range: none).
        conflicts: the conflict areas at links that yield which the ego's front may enter in
            the coming step (at most its speed plus its hardest acceleration ahead), each with
            a foe whose link has priority over the ego's (what the yield-violation judge
            reads).
    """

    leader_gap_m: float = S.SENSOR_RANGE_M
    conflicts: tuple[Conflict, ...] = ()


NO_YIELD = YieldReading()
"""The reading with no yield line in force and no conflict ahead."""


class YieldSensor:
    """The yield lines ahead where the ego must let a foe pass this step, and the conflict
    areas it may enter.

    Args:
        junctions: ``(junction id, route position of its stop line [m], route position of
            the edge out of it [m])`` of the route's junctions, in route order.
        ego_length_m: the ego's length [m].
        unregulated: the ids of the route's ``unregulated`` junctions (module docstring).
    """

    def __init__(
        self,
        junctions: Iterable[tuple[str, float, float]],
        ego_length_m: float,
        unregulated: frozenset[str] = frozenset(),
    ) -> None:
        self.junctions = tuple(junctions)
        self.ego_length_m = ego_length_m
        self.unregulated = unregulated
        self._types: dict[str, tuple[float, float]] = {}  # foe id -> (accel, length)
        self._link_states: dict[str, str] = {}  # junction -> the ego's link, last read ahead
        self._vias: dict[str, str] = {}  # junction -> the ego's via lane, last read ahead
        self._turns: dict[str, TurnGeometry | None] = {}  # via lane -> its turn, if one

    def line_gap(self, junction: str, pos_m: float) -> float | None:
        """[m] from route position ``pos_m`` to the stop line of the next passage through
        ``junction`` (``None``: none ahead)."""
        for node, line_m, _end_m in self.junctions:
            if node == junction and line_m >= pos_m:
                return line_m - pos_m
        return None

    def passing(self, pos_m: float) -> tuple[str, float] | None:
        """The junction route position ``pos_m`` lies in, past its stop line, if the ego's
        link into it yielded when last read before the line: its id and where it ends [m]."""
        for node, line_m, end_m in self.junctions:
            if line_m < pos_m < end_m:
                state = self._link_states.get(node, "")
                return (node, end_m) if link_yields(state) else None
        return None

    def foe_motion(self, api: Any, foe: JunctionFoe) -> FoeMotion:
        """A foe's :class:`FoeMotion`, read from the simulation."""
        kept = self._types.get(foe.foe_id)
        if kept is None:
            accel = float(api.vehicle.getAccel(foe.foe_id)) or FOE_ACCEL_MPS2
            kept = self._types[foe.foe_id] = (accel, float(api.vehicle.getLength(foe.foe_id)))
        state = ""
        if not api.vehicle.getLaneID(foe.foe_id).startswith(":"):
            junction = junction_of(foe.foe_lane)
            for link in api.vehicle.getNextLinks(foe.foe_id):
                if junction_of(link[4]) == junction:
                    state = link[5]
                    break
        return FoeMotion(
            float(api.vehicle.getSpeed(foe.foe_id)), kept[0],
            float(api.vehicle.getAllowedSpeed(foe.foe_id)), kept[1], state,
        )  # fmt: skip

    def horizon(self, links: Iterable[Any], pos_m: float) -> tuple[dict[str, str], float]:
        """The yielding links of the junction the ego is passing (:meth:`passing`) and among
        ``links`` (``vehicle.getNextLinks``, in route order) within sensor range and before
        the first unregulated junction: junction id -> link state, and how far to look for
        their foes [m] (to the end of the last one). Each link's state is kept for
        :meth:`passing`."""
        states: dict[str, str] = {}
        reach = 0.0
        inside = self.passing(pos_m)
        if inside is not None:
            states[inside[0]] = self._link_states[inside[0]]
            reach = inside[1] - pos_m + 1.0  # [m] to its end, and a metre
        for link in links:
            junction, state = junction_of(link[4]), link[5]
            gap = self.line_gap(junction, pos_m)
            if gap is None:  # a link out of the junction the ego is in: no line ahead
                continue
            if gap >= S.SENSOR_RANGE_M or junction in self.unregulated:
                break
            self._link_states[junction] = state
            self._vias[junction] = str(link[4])
            if link_yields(state):
                states[junction] = state
                reach = gap + float(link[7]) + 1.0  # [m] its whole length, and a metre
        return states, reach

    def line_at(self, junction: str, pos_m: float) -> float | None:
        """[m] The route position of the stop line of the passage through ``junction`` that
        the ego (its front at route position ``pos_m``) is before or in (``None``: none)."""
        for node, line_m, end_m in self.junctions:
            if node == junction and pos_m < end_m:
                return line_m
        return None

    def turn(self, api: Any, via: str) -> TurnGeometry | None:
        """The :class:`TurnGeometry` of the ego's via lane ``via`` (read once, then kept)."""
        if via not in self._turns:
            self._turns[via] = turn_geometry(api, via)
        return self._turns[via]

    def turn_at(self, api: Any, junction: str, pos_m: float) -> tuple[TurnGeometry, float] | None:
        """The turn of the ego's link through ``junction`` and the route position of its stop
        line [m] (``None``: the link leads to no internal junction, or the passage is
        behind the ego's front at route position ``pos_m``)."""
        via = self._vias.get(junction, "")
        turn = self.turn(api, via) if via else None
        line_m = self.line_at(junction, pos_m)
        return None if turn is None or line_m is None else (turn, line_m)

    def wait_gap(self, api: Any, junction: str, foe: JunctionFoe, pos_m: float) -> float | None:
        """[m] From the ego's front (at route position ``pos_m``) to where it waits for
        ``foe``: the stop line of ``junction``, or for a foe of its turn (``foe.turning``) the
        turn's internal junction or the start of their conflict area, whichever comes first
        (``None``: nothing ahead)."""
        if not foe.turning:
            return self.line_gap(junction, pos_m)
        found = self.turn_at(api, junction, pos_m)
        if found is None:
            return None
        gap = min(foe.ego_dist_m, found[1] + found[0].via_m - pos_m)
        return gap if gap >= 0.0 else None

    def turn_foes(self, api: Any, junction: str, pos_m: float) -> list[JunctionFoe]:
        """The foes with priority at the internal junction of the ego's turn through
        ``junction`` (module docstring): the vehicles on a foe's incoming lane bound for its
        crossing via lane, and those on that via lane."""
        found = self.turn_at(api, junction, pos_m)
        if found is None:
            return []
        turn, line_m = found
        foes: list[JunctionFoe] = []
        for incoming, foe_via, foe_at, ego_at in turn.foes:
            to_entry = float(api.lane.getLength(incoming))
            near = []
            for vid in api.lane.getLastStepVehicleIDs(incoming):
                links = api.vehicle.getNextLinks(vid)
                dist = to_entry - float(api.vehicle.getLanePosition(vid))
                if (
                    links
                    and links[0][4] == foe_via
                    and not stops_at_signal(api, vid, links[0][5], dist)
                ):
                    near.append((vid, dist))
            near += [(vid, -float(api.vehicle.getLanePosition(vid)))
                     for vid in api.lane.getLastStepVehicleIDs(foe_via)]  # fmt: skip
            foes += [turn_foe(vid, foe_via, foe_at, ego_at, dist, line_m - pos_m,
                              turn.inner_lane) for vid, dist in near]  # fmt: skip
        return foes

    def foes(
        self, api: Any, states: dict[str, str], reach: float, pos_m: float
    ) -> list[JunctionFoe]:
        """The foes at the yielding links ``states`` (:meth:`horizon`): SUMO's
        (``vehicle.getJunctionFoes`` up to ``reach``) and those of a turn's internal
        junction (:meth:`turn_foes`)."""
        found = [JunctionFoe(*raw) for raw in api.vehicle.getJunctionFoes(EGO_ID, reach)]
        for junction in states:
            found.extend(self.turn_foes(api, junction, pos_m))
        return found

    def __call__(
        self,
        api: Any,
        pos_m: float,
        speed_mps: float,
        limit_mps: float,
        next_links: Sequence[Any],
    ) -> YieldReading:
        """The yield lines ahead of the ego's front (at route position ``pos_m``) where it
        must yield now (:func:`must_yield`), the nearest it can still stop before being a
        leader, and the conflict areas it may enter in the coming step with a foe that has
        priority (for :func:`enters_in_front`); ``next_links``: the ego's
        ``vehicle.getNextLinks`` this step."""
        states, reach = self.horizon(next_links, pos_m)
        if not states:
            return NO_YIELD
        entry_reach_m = (speed_mps + MAX_ACCEL_MPS) * STEP_LENGTH_S  # the most a step covers
        leader, conflicts = S.SENSOR_RANGE_M, []
        for foe in self.foes(api, states, reach, pos_m):
            junction = junction_of(foe.ego_lane)
            state = states.get(junction)
            if state is None or not foe.ego_responds:
                continue
            motion = None
            if 0.0 < foe.ego_dist_m <= entry_reach_m:
                motion = self.foe_motion(api, foe)
                conflicts.append(Conflict(foe, motion))
            gap = self.wait_gap(api, junction, foe, pos_m)
            if gap is None or gap >= leader or not can_stop_before(speed_mps, gap):
                continue
            motion = motion or self.foe_motion(api, foe)
            if must_yield(state, foe, motion, speed_mps, limit_mps, self.ego_length_m):
                leader = gap
        return YieldReading(leader, tuple(conflicts))
