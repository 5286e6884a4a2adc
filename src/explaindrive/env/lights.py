"""When a light ahead is a virtual leader: the decision at yellow.

The paper places a zero-length virtual leader at the stop line of a red or yellow light,
after Treiber and Kesting's traffic-light model, in which a driver who sees the light turn
yellow decides once whether to stop: only a driver who can still stop before the line
treats it as a standing vehicle. One who cannot (the dilemma zone) drives through, since
braking would leave the car on the junction at red. :class:`AmberDecision` makes that
decision when the ego first sees a light yellow, with the ego's hardest braking
(:func:`~explaindrive.env.actions.can_stop_before`, the rule the run-time shield uses),
and keeps it while that light stays yellow. A red light is always a virtual leader.

``YELLOW_LEADERS`` names the rules an environment can use: ``decided`` (the above, the
default), ``gentle`` and ``always``, the paper's own leader at every yellow.

``gentle`` decides as a passenger would have it: the car stops where it can do so braking at
:data:`GENTLE_BRAKE_MPS` per step, and also where it could stop only braking harder but could
not clear the line within :data:`CLEAR_STEPS` steps at its speed (a yellow lasts at least
3 s, so a car that clears within 2 s is across before red). Where it goes, the light does not
bind it for the rest of that yellow, and the ego is shown the light as green
(:meth:`AmberDecision.shown_colour`): the safety rules and the driver then treat the light as
the decision has it, with no hard braking for a yellow it may legally drive through.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from dataclasses import dataclass, field

from explaindrive.env.actions import STOP_MARGIN_M, braking_distance, can_stop_before
from explaindrive.env.state import LightState

YELLOW_LEADERS: tuple[str, ...] = ("decided", "gentle", "always")
"""When a yellow light is a virtual leader: ``decided`` once by :class:`AmberDecision` with
the hardest braking, ``gentle`` once with gentle braking, or ``always`` (the paper)."""
DEFAULT_YELLOW_LEADER = "decided"
GENTLE_BRAKE_MPS = 2.0  # [m/s per step] the braking a ``gentle`` stop at yellow may ask for
CLEAR_STEPS = 2  # steps within which a car going through a ``gentle`` yellow clears the line
CLEAR_SLACK_M = 1.0  # [m] it clears the line by at least this much at its speed


def stops_gently(speed_mps: float, d_tl: float) -> bool:
    """Whether a car at ``speed_mps`` can stand :data:`STOP_MARGIN_M` before a line ``d_tl``
    ahead braking by :data:`GENTLE_BRAKE_MPS` per step from now on."""
    v = max(speed_mps - GENTLE_BRAKE_MPS, 0.0)
    need = v + braking_distance(v, GENTLE_BRAKE_MPS) + STOP_MARGIN_M if v > 0.0 else 0.0
    return need <= d_tl


def clears(speed_mps: float, d_tl: float) -> bool:
    """Whether a car keeping ``speed_mps`` is :data:`CLEAR_SLACK_M` past a line ``d_tl``
    ahead within :data:`CLEAR_STEPS` steps."""
    return CLEAR_STEPS * speed_mps >= d_tl + CLEAR_SLACK_M


@dataclass(slots=True)
class AmberDecision:
    """The ego's decisions at the yellow of the lights ahead, each kept until its yellow ends.

    A joined cluster (one programme for several nearby junctions) has several stop lines on
    the ego's way, and one yellow starts at all of them: each line is decided when its yellow
    is first seen, at its own distance, so a car that is committed at the first line but can
    stop before the next one stops there (the next line is a leader while the first is
    shown green), and does not meet the next line's yellow, already half over, as new.
    """

    decided: dict[Hashable, bool] = field(default_factory=dict)
    """light -> whether the ego stops for its yellow (in the env, a light is a signalled
    link: its traffic light id and link index)."""
    always: bool = False
    """Every yellow is a leader (the paper's rule): nothing is decided."""
    gentle: bool = False
    """Decide by the ``gentle`` rule (module docstring) instead of the hardest braking."""

    def decide(self, speed_mps: float, d_tl: float) -> bool:
        """Whether the ego, at ``speed_mps`` and ``d_tl`` [m] from a stop line whose light
        has just turned yellow, stops for it."""
        stops = can_stop_before(speed_mps, d_tl)
        if self.gentle:
            stops = stops and (stops_gently(speed_mps, d_tl) or not clears(speed_mps, d_tl))
        return stops

    def leaders(
        self, seen: Sequence[tuple[Hashable, LightState, float]], speed_mps: float
    ) -> list[bool]:
        """Whether the stop line of each light of ``seen`` is a virtual leader this step.

        Args:
            seen: ``(light, its colour this step, [m] from the ego's front to its stop
                line)`` of the lights ahead this step (a light of ``None``: none in range;
                its colour is then green). A decision about a light that is not among them
                yellow is forgotten: its next yellow is decided afresh.
            speed_mps: the ego's speed.
        """
        yellow = {light for light, colour, _d in seen if colour is LightState.YELLOW}
        for light in [light for light in self.decided if light not in yellow]:
            del self.decided[light]
        flags = []
        for light, colour, d_tl in seen:
            if colour is not LightState.YELLOW:
                flags.append(colour is LightState.RED)
            elif self.always:
                flags.append(True)
            else:
                if light not in self.decided:
                    self.decided[light] = self.decide(speed_mps, d_tl)
                flags.append(self.decided[light])
        return flags

    def is_leader(
        self, light_id: Hashable | None, colour: LightState, speed_mps: float, d_tl: float
    ) -> bool:
        """Whether the stop line of light ``light_id``, the only one ahead, is a virtual
        leader this step (:meth:`leaders`)."""
        return self.leaders([(light_id, colour, d_tl)], speed_mps)[0]

    def shown_colour(self, colour: LightState, leader: bool) -> LightState:
        """The colour the ego is shown for a light whose line :meth:`is_leader` just judged:
        under the ``gentle`` rule a yellow it goes through is shown green; else ``colour``."""
        if self.gentle and colour is LightState.YELLOW and not leader:
            return LightState.GREEN
        return colour

    @classmethod
    def for_rule(cls, rule: str) -> AmberDecision:
        """The decision of one of :data:`YELLOW_LEADERS`.

        Raises:
            ValueError: for another name.
        """
        if rule not in YELLOW_LEADERS:
            raise ValueError(f"unknown yellow rule {rule!r}; expected one of {YELLOW_LEADERS}")
        return cls(always=rule == "always", gentle=rule == "gentle")
