"""The ego's violations in one step: collision, red-light run, pedestrian yield, right of
way, speeding.

Red lights, crossings and the right of way are judged on what the ego saw before the
step's observation: a violation is crossing a stop line during the step while the light was
red, or while a pedestrian was in, or stepping into, the ego's lane on the crossing. A light
is judged on the link the ego perceived (:func:`~explaindrive.env.perception.signal_links`):
the stop line and signal index of its lane's link, as the observation reads them. A yield
violation is the ego's front entering, during the step, a conflict area of a junction it
entered by a link that yields, in front of a foe with priority that had not left the area
and would reach it, at its speed, within SUMO's own gap after the ego's back has left it
(:func:`~explaindrive.env.right_of_way.enters_in_front`; whether or not the ego could still
stop: a foe seen too late counts too).

Each step has a site (:data:`~explaindrive.env.metrics.SITES`), where its violations are
counted: a red-light run at its signal; a pedestrian-yield violation at its crossing's
junction (``signal`` where a light controls it, else ``crossing``); anything else where the
ego's front is after the step: inside a junction's area (from its stop line to the next
edge), ``signal``, ``crossing`` (an unsignalised junction with a pedestrian crossing over
the route, such as a zebra) or ``yield_junction`` (any other junction without a light),
else ``free_road``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from explaindrive.env.actions import STEP_LENGTH_S
from explaindrive.env.perception import CrossingSensor, SignalLink, link_colour
from explaindrive.env.right_of_way import Conflict, enters_in_front
from explaindrive.env.state import LightState
from explaindrive.sim.route import RouteCrossing, RouteGeometry
from explaindrive.sim.scenario.files import EGO_ID

SPEEDING_TOLERANCE_MPS = 1e-6  # [m/s] above the legal limit by more than this is speeding


def ego_collided(api: Any) -> bool:
    """Whether the ego is in one of the collisions SUMO reported this step."""
    return any(EGO_ID in (col.collider, col.victim) for col in api.simulation.getCollisions())


def speeding(speed_mps: float, legal_limit_mps: float) -> bool:
    """Whether ``speed_mps`` is above the legal limit."""
    return speed_mps > legal_limit_mps + SPEEDING_TOLERANCE_MPS


@dataclass(slots=True)  # built every step: not frozen (a frozen __init__ costs 5x as much)
class Violations:
    """The traffic-rule violations of one step and the step's site (one of
    :data:`~explaindrive.env.metrics.SITES`)."""

    red_light_run: bool
    ped_violation: bool
    site: str = "free_road"
    yield_violation: bool = False

    @property
    def any(self) -> bool:
        """A rule of way was broken: a red-light run, a pedestrian-yield or a yield violation
        (what the reward's traffic term charges)."""
        return self.red_light_run or self.ped_violation or self.yield_violation


class ViolationJudge:
    """Judges the ego's passage over the stop lines and through the junctions of its route.

    Args:
        crossings: the crossing sensor of the episode.
        geometry: the route's geometry (its junctions give the sites).
        ego_length_m: the ego's length [m] (how long its back takes to leave a conflict).
    """

    def __init__(
        self, crossings: CrossingSensor, geometry: RouteGeometry, ego_length_m: float
    ) -> None:
        self.crossings = crossings
        self.geometry = geometry
        self.ego_length_m = ego_length_m
        self._travelled_m: float | None = None  # the ego's travel in the step before [m]

    def __call__(
        self,
        api: Any,
        prev_pos_m: float,
        pos_m: float,
        links: tuple[SignalLink, ...],
        in_lane: dict[str, bool],
        conflicts: tuple[Conflict, ...] = (),
    ) -> Violations:
        """The violations of a step that moved the ego's front from ``prev_pos_m`` to
        ``pos_m`` (route positions [m]); ``links``, ``in_lane`` and ``conflicts`` (the
        conflict areas it might enter, ``YieldReading.conflicts``) are what the ego perceived
        before the step (:class:`~explaindrive.env.perception.Percept`)."""
        red = self.ran_red_light(api, links, pos_m - prev_pos_m)
        cut_in = self.entered_in_front(conflicts, pos_m - prev_pos_m)
        ped = self.crossed_occupied(api, prev_pos_m, pos_m, in_lane)
        if red:
            site = "signal"
        elif ped:
            crossing = self._crossed(prev_pos_m, pos_m)
            site = "signal" if crossing is not None and crossing.signalized else "crossing"
        else:
            site = self.site_at(pos_m)
        return Violations(red, ped, site, yield_violation=cut_in)

    def entered_in_front(self, conflicts: tuple[Conflict, ...], travelled_m: float) -> bool:
        """The ego's front, travelling ``travelled_m`` this step, entered one of
        ``conflicts`` in front of its foe with priority
        (:func:`~explaindrive.env.right_of_way.enters_in_front`; called once a step: the
        ego's acceleration is its travel's rise since the step before)."""
        before, self._travelled_m = self._travelled_m, travelled_m
        accel = 0.0 if before is None else (travelled_m - before) / STEP_LENGTH_S**2
        return any(
            enters_in_front(c.foe, c.motion, travelled_m, self.ego_length_m, accel)
            for c in conflicts
        )

    def site_at(self, pos_m: float) -> str:
        """The site of route position ``pos_m`` (module docstring)."""
        junction = self.geometry.junction_at(pos_m)
        if junction is None:
            return "free_road"
        if junction.signalized:
            return "signal"
        return "crossing" if junction.crossing else "yield_junction"

    def _crossed(self, prev_pos_m: float, pos_m: float) -> RouteCrossing | None:
        """The crossing whose stop line the ego's front crossed this step, if any."""
        for crossing in self.crossings.crossings:
            if prev_pos_m < crossing.stop_line_m <= pos_m:
                return crossing
        return None

    @staticmethod
    def ran_red_light(api: Any, links: tuple[SignalLink, ...], travelled_m: float) -> bool:
        """The ego's front crossed the stop line of one of ``links`` (its links before the
        step, nearest first) while travelling ``travelled_m`` this step, and that link's
        light was red.

        SUMO switches signals at the start of a step and then moves the cars, so the
        colour read after the step is the one that held while the ego crossed.
        """
        for link in links:
            if link.gap_m > travelled_m:
                break
            if link.gap_m > 0.0 and link_colour(api, link) is LightState.RED:
                return True
        return False

    def crossed_occupied(
        self, api: Any, prev_pos_m: float, pos_m: float, in_lane: dict[str, bool]
    ) -> bool:
        """The ego's front crossed a crossing's stop line during this step while a
        pedestrian was in, or stepping into, its lane (before or after the step)."""
        crossing = self._crossed(prev_pos_m, pos_m)
        if crossing is None:
            return False
        on_crossing = self.crossings.persons(api, crossing.crossing_edge)
        return in_lane.get(crossing.crossing_edge, False) or (
            bool(on_crossing) and self.crossings.in_lane(api, crossing, on_crossing)
        )
