"""When a light ahead is a virtual leader: the decision at yellow.

The paper places a zero-length virtual leader at the stop line of a red or yellow light,
after Treiber and Kesting's traffic-light model, in which a driver who sees the light turn
yellow decides once whether to stop: only a driver who can still stop before the line
treats it as a standing vehicle. One who cannot (the dilemma zone) drives through, since
braking would leave the car on the junction at red. :class:`AmberDecision` makes that
decision when the ego first sees a light yellow, with the ego's hardest braking
(:func:`~explaindrive.env.actions.can_stop_before`, the rule the run-time shield uses),
and keeps it while that light stays yellow. A red light is always a virtual leader.

``YELLOW_LEADERS`` names the two rules an environment can use: ``decided`` (the above, the
default) and ``always``, the paper's own leader at every yellow.
"""

from __future__ import annotations

from dataclasses import dataclass

from explaindrive.env.actions import can_stop_before
from explaindrive.env.state import LightState

YELLOW_LEADERS: tuple[str, ...] = ("decided", "always")
"""When a yellow light is a virtual leader: ``decided`` once by :class:`AmberDecision`, or
``always`` (the paper)."""
DEFAULT_YELLOW_LEADER = "decided"


@dataclass(slots=True)
class AmberDecision:
    """The ego's decision at the yellow of the light ahead, kept until that yellow ends."""

    light_id: str | None = None
    """The light the decision is about (``None``: no yellow decided)."""
    stops: bool = True
    """Whether the ego stops for that light's yellow."""
    always: bool = False
    """Every yellow is a leader (the paper's rule): nothing is decided."""

    def is_leader(
        self, light_id: str | None, colour: LightState, speed_mps: float, d_tl: float
    ) -> bool:
        """Whether the stop line of light ``light_id`` ahead is a virtual leader this step.

        Args:
            light_id: the light ahead within sensor range (``None``: none in range; its
                colour is then green, and the next yellow is decided afresh).
            colour: its colour this step.
            speed_mps: the ego's speed.
            d_tl: [m] from the ego's front to its stop line.
        """
        if colour is not LightState.YELLOW:
            self.light_id = None
            return colour is LightState.RED
        if self.always:
            return True
        if self.light_id != light_id:
            self.light_id, self.stops = light_id, can_stop_before(speed_mps, d_tl)
        return self.stops
