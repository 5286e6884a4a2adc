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
is none either: SUMO's drivers wait inside a junction for a left turn at its internal
junction, which the ego does not model.

``getJunctionFoes`` is asked only when a yielding link lies within sensor range, and only as
far as the last such link: SUMO 1.28's libsumo crashes (a segmentation fault) when its
look-ahead reaches an ``unregulated`` junction (one without junction logic, such as the
centre of netgenerate's spider networks), so the look-ahead also stops before the first one
on the route; a yielding link beyond it is read once the ego has passed it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, NamedTuple

from explaindrive.env import state as S
from explaindrive.env.actions import SPEED_CHANGES_MPS, STEP_LENGTH_S, can_stop_before
from explaindrive.sim.scenario.files import EGO_ID

FOE_MOVING_MPS = 0.1
"""[m/s] A foe slower than this is standing: it does not leave the conflict on its own."""
YIELD_JUDGE_GAP_S = 1.0
"""[s] The gap a yield violation breaks: SUMO's default ``jmTimegapMinor``, the time its own
drivers keep ahead of a prioritised vehicle. The judge is SUMO's rule, so SUMO's drivers are
not flagged for what they are built to do; the ego perceives with :data:`YIELD_MARGIN_S`."""
YIELD_MARGIN_S = 2.0
"""[s] A foe with priority must reach the conflict at least this long after the ego has left
it: SUMO's default ``jmTimegapMinor`` (1 s), the gap its Krauss drivers keep ahead of a
prioritised vehicle, plus 1 s because the policy may not accelerate as hard as the clearing
time assumes."""
MAX_ACCEL_MPS = max(SPEED_CHANGES_MPS)  # [m/s per step] the ego's hardest acceleration
FOE_ACCEL_MPS2 = 2.6  # [m/s^2] a foe's acceleration when SUMO gives none (its default)
YIELD_STATES = frozenset("gmsw=oZ")  # the ego's link states that yield to foes with priority
NO_SIGNAL_STATES = frozenset("rRu")  # a foe at red or red-yellow does not enter
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
    margin_s: float = YIELD_MARGIN_S,
) -> bool:
    """The rule (module docstring): whether the ego must let ``foe`` pass before it enters.

    Args:
        ego_link_state: the state of the ego's link into the junction.
        foe: the foe and the conflict.
        motion: the foe's speed, acceleration, top speed, length and link state.
        ego_speed_mps: the ego's speed.
        ego_limit_mps: the ego's posted limit (its top speed through the junction).
        ego_length_m: the ego's length.
        margin_s: the gap the foe must arrive after the ego has cleared the conflict:
            :data:`YIELD_MARGIN_S` to perceive, :data:`YIELD_JUDGE_GAP_S` to judge.
    """
    if not link_yields(ego_link_state) or not foe.ego_responds:
        return False
    if motion.link_state in NO_SIGNAL_STATES:
        return False
    foe_out_m = foe.foe_exit_m + motion.length_m  # until its back has left the conflict
    if foe_out_m <= 0.0:
        return False
    ego_arrives = clear_time_s(foe.ego_dist_m, ego_speed_mps, ego_limit_mps)
    foe_leaves = foe_out_m / motion.speed_mps if motion.speed_mps > FOE_MOVING_MPS else math.inf
    if foe_leaves + margin_s <= ego_arrives:  # it will be gone before the ego comes
        return False
    ego_clear = clear_time_s(foe.ego_exit_m + ego_length_m, ego_speed_mps, ego_limit_mps)
    foe_arrives = arrival_time_s(
        foe.foe_dist_m, motion.speed_mps, motion.accel_mps2, motion.max_speed_mps
    )
    return foe_arrives < ego_clear + margin_s


class YieldReading(NamedTuple):
    """The yield lines ahead this step [m] from the ego's front (sensor range: none).

    Attributes:
        leader_gap_m: to the nearest where the ego must yield and can still stop: a
            virtual leader.
        due_gap_m: to the nearest where a foe with priority is within SUMO's own gap
            (:data:`YIELD_JUDGE_GAP_S`), whether or not the ego can still stop (what the
            yield-violation judge reads).
    """

    leader_gap_m: float = S.SENSOR_RANGE_M
    due_gap_m: float = S.SENSOR_RANGE_M


NO_YIELD = YieldReading()
"""The reading with no yield line in force."""


class YieldSensor:
    """The yield lines ahead where the ego must let a foe pass this step.

    Args:
        lines: ``(junction id, route position of its stop line [m])`` of the route's
            junctions, in route order.
        ego_length_m: the ego's length [m].
        unregulated: the ids of the route's ``unregulated`` junctions (module docstring).
    """

    def __init__(
        self,
        lines: Iterable[tuple[str, float]],
        ego_length_m: float,
        unregulated: frozenset[str] = frozenset(),
    ) -> None:
        self.lines = tuple(lines)
        self.ego_length_m = ego_length_m
        self.unregulated = unregulated
        self._types: dict[str, tuple[float, float]] = {}  # foe id -> (accel, length)

    def line_gap(self, junction: str, pos_m: float) -> float | None:
        """[m] from route position ``pos_m`` to the stop line of the next passage through
        ``junction`` (``None``: none ahead)."""
        for node, line_m in self.lines:
            if node == junction and line_m >= pos_m:
                return line_m - pos_m
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
        """The yielding links among ``links`` (``vehicle.getNextLinks``, in route order)
        within sensor range and before the first unregulated junction: junction id -> link
        state, and how far to look for their foes [m] (to the end of the last one)."""
        states: dict[str, str] = {}
        reach = 0.0
        for link in links:
            junction, state = junction_of(link[4]), link[5]
            gap = self.line_gap(junction, pos_m)
            if gap is None:  # a link out of the junction the ego is in: no line ahead
                continue
            if gap >= S.SENSOR_RANGE_M or junction in self.unregulated:
                break
            if link_yields(state):
                states[junction] = state
                reach = gap + float(link[7]) + 1.0  # [m] its whole length, and a metre
        return states, reach

    def __call__(self, api: Any, pos_m: float, speed_mps: float, limit_mps: float) -> YieldReading:
        """The yield lines ahead of the ego's front (at route position ``pos_m``) where it
        must yield now (:func:`must_yield`): the nearest it can still stop before (a leader)
        and the nearest of all."""
        states, reach = self.horizon(api.vehicle.getNextLinks(EGO_ID), pos_m)
        if not states:
            return NO_YIELD
        foes = api.vehicle.getJunctionFoes(EGO_ID, reach)
        leader = due = S.SENSOR_RANGE_M
        for raw in foes:
            foe = JunctionFoe(*raw)
            junction = junction_of(foe.ego_lane)
            state = states.get(junction)
            if state is None or not link_yields(state) or not foe.ego_responds:
                continue
            gap = self.line_gap(junction, pos_m)
            if gap is None or gap >= leader:
                continue
            motion = self.foe_motion(api, foe)
            args = (state, foe, motion, speed_mps, limit_mps, self.ego_length_m)
            if must_yield(*args):
                if can_stop_before(speed_mps, gap):
                    leader = gap
                if must_yield(*args, margin_s=YIELD_JUDGE_GAP_S):
                    due = min(due, gap)
        return YieldReading(leader, due)
