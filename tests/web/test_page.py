"""The page offers the evaluation grid's traffic levels and the seed range from the code."""

from __future__ import annotations

import re

from explaindrive.limits import MAX_SEED
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS
from explaindrive.web.page import render_page, traffic_options


def test_traffic_options_mark_the_selected_level() -> None:
    assert traffic_options((0.5, 1.25), 1.25) == (
        '<option value="0.5">0.5</option>\n          <option value="1.25" selected>1.25</option>'
    )


def test_the_page_offers_the_grid_and_the_seed_range() -> None:
    html = render_page()
    values = re.findall(r'<option value="([0-9.]+)"', html)
    assert [float(v) for v in values] == list(TRAFFIC_LEVELS)
    assert re.findall(r'<option value="([0-9.]+)" selected>', html) == ["1.0"]
    assert f'max="{MAX_SEED}"' in html and "<!--" not in html
