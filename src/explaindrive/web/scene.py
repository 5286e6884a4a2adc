"""What the page draws: the scene of :mod:`explaindrive.sim.scene`, which the environment's
top-down rendering shares."""

from explaindrive.sim.scene import (
    EGO_ID,
    VIEW_RADIUS_M,
    Scene,
    SignalHead,
    load_scene,
    signal_colour,
    snapshot,
)

__all__ = [
    "EGO_ID",
    "VIEW_RADIUS_M",
    "Scene",
    "SignalHead",
    "load_scene",
    "signal_colour",
    "snapshot",
]
