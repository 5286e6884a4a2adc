"""The passenger page, with the choices it offers filled in from their one home.

``static/index.html`` marks where the traffic levels (the evaluation grid's,
:data:`~explaindrive.sim.scenario.layout.TRAFFIC_LEVELS`, the ride's default selected) and
the largest seed go; :func:`render_page` fills them in.
"""

from __future__ import annotations

import functools
from pathlib import Path

from explaindrive.limits import MAX_SEED
from explaindrive.ride.config import RideConfig
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS

STATIC_DIR = Path(__file__).parent / "static"
TRAFFIC_MARK = "<!-- traffic-options -->"
MAX_SEED_MARK = "<!-- max-seed -->"


def traffic_options(levels: tuple[float, ...], selected: float) -> str:
    """The ``<option>`` lines of the traffic menu, ``selected`` marked.

    >>> traffic_options((0.5, 1.0), 1.0)
    '<option value="0.5">0.5</option>\\n          <option value="1.0" selected>1.0</option>'
    """
    lines = [
        f'<option value="{level}"{" selected" if level == selected else ""}>{level}</option>'
        for level in levels
    ]
    return "\n          ".join(lines)


@functools.cache
def render_page() -> str:
    """The page's HTML with the traffic levels and the seed range filled in."""
    html = (STATIC_DIR / "index.html").read_text(encoding="utf-8")
    options = traffic_options(TRAFFIC_LEVELS, RideConfig().traffic_level)
    return html.replace(TRAFFIC_MARK, options).replace(MAX_SEED_MARK, str(MAX_SEED))
