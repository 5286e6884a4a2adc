"""A ride on a network of your own: a netgenerate grid through three lights."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from explaindrive.agent.controller import MergedController
from explaindrive.language.stack import make_language_stack
from explaindrive.ride.config import RideConfig
from explaindrive.ride.runner import run_ride
from explaindrive.ride.script import default_script_path, load_script
from explaindrive.ride.session import RideSession

from ..conftest import GRID_WITH_LIGHTS


def test_the_default_ride_on_a_netgenerate_grid(
    netgen: Callable[..., Path], tmp_path: Path
) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS)
    config = RideConfig(seed=3, net_file=str(net), route=("A1B1", "D1E1"))
    language = make_language_stack("embedded").load(speech=False)
    session = RideSession(config, MergedController.from_package(), language)
    out = run_ride(session, load_script(default_script_path()), tmp_path)

    confirmed = [e["to"] for r in session.records for e in r.passenger if e["type"] == "confirmed"]
    assert confirmed == ["fast", "stop", "comfort"]
    summary = json.loads(out.summary.read_text())
    metrics = summary["metrics"]
    assert metrics["collisions"] == 0 and metrics["red_light_runs"] == 0
    assert metrics["ped_violations"] == 0
    # the route crosses three signalised junctions (B1, C1, D1): the car meets their lights
    lights = {r.explanation["factor"] for r in session.records if r.explanation}
    assert "traffic_light" in lights, lights
