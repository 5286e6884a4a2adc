"""Ranges every scenario shares: traffic levels and seeds.

Kept apart from the layout so that the config layer can check them without importing a
scenario.
"""

from __future__ import annotations

import math
import numbers

TRAFFIC_LEVELS: tuple[float, ...] = (0.5, 0.75, 1.0, 1.25, 1.5)
"""The paper's five traffic levels (1.0 = 900 veh/h on the main road)."""
MAX_TRAFFIC_LEVEL = 2.0
"""The busiest level a scenario accepts: at 2.0 the ego entered the paper's road in every one
of seeds 0-49 (with the departure rule of :data:`SATURATED_LEVEL`)."""
SATURATED_LEVEL = 1.75
"""Above this level the demand outgrows the roads: when the ego's entry is cleared (after
each 10 s without a gap), the background vehicles still waiting to enter on its first edge
are dropped too, since SUMO inserts them before the ego; without that the first road of the
paper's stayed blocked for the ego in 7 of seeds 0-39 at 2.0. At and below it nothing
changes."""
SEED_LIMIT = 2**31
"""SUMO's seeds are integers in [0, SEED_LIMIT)."""


def validate_traffic_level(level: float) -> float:
    """Return ``level`` as a float if it is in (0, :data:`MAX_TRAFFIC_LEVEL`].

    Raises:
        ValueError: naming the range, otherwise.
    """
    if isinstance(level, bool) or not isinstance(level, int | float) or not math.isfinite(level):
        raise ValueError(f"traffic level must be a finite number > 0, got {level!r}")
    if level <= 0:
        raise ValueError(f"traffic level must be > 0, got {level:g}")
    if level > MAX_TRAFFIC_LEVEL:
        raise ValueError(
            f"traffic level must be at most {MAX_TRAFFIC_LEVEL:g}, got {level:g}: on a busier "
            "road the ego cannot enter"
        )
    return float(level)


def validate_seed(seed: object) -> int:
    """Return ``seed`` as an int if it is an integer in [0, :data:`SEED_LIMIT`).

    Raises:
        ValueError: otherwise.
    """
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise ValueError(f"seed must be an integer in [0, 2**31), got {seed!r}")
    if not 0 <= int(seed) < SEED_LIMIT:
        raise ValueError(f"seed must be an integer in [0, 2**31), got {seed!r}")
    return int(seed)
