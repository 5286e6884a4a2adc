"""The env on networks of SUMO's netgenerate: routes, lights and demand of their own."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

from explaindrive.env import state as S
from explaindrive.env.scripted import CautiousDriver
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.sim.sumo_home import sumo_home
from tests.conftest import GRID_WITH_LIGHTS


def test_a_grid_route_with_generated_trips(
    make_env: Callable[..., UrbanDriveEnv], netgen: Callable[..., Path]
) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS)
    env = make_env(net_file=net, route=("A1B1", "D1E1"), max_steps=20, warmup_s=60)
    obs, info = env.reset(seed=0)
    assert info["scenario"] == "grid.net.xml:A1B1->D1E1"
    # the first light B1 lies at the end of the first block: 200 m minus 14.4 m of junction
    assert obs[S.D_TL] == 185.6 - env.route_pos_m
    assert env.sumo.simulation.getTime() == 61.0  # warm-up, then one step to enter
    assert env.sumo.vehicle.getIDCount() > 1  # background trips are running


def test_the_episode_starts_where_the_demand_does(
    make_env: Callable[..., UrbanDriveEnv], netgen: Callable[..., Path], tmp_path: Path
) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS)
    demand = tmp_path / "morning.rou.xml"
    script = sumo_home() / "tools" / "randomTrips.py"
    subprocess.run([sys.executable, str(script), "-n", str(net), "-r", str(demand),
                    "-o", str(tmp_path / "trips.xml"), "--begin", "25200", "--end", "25800",
                    "--period", "4", "--seed", "1"], check=True, capture_output=True,
                   cwd=tmp_path)  # fmt: skip
    env = make_env(net_file=net, route=("A1B1", "D1E1"), demand_file=demand, warmup_s=60)
    for level in (1.0, 1.5):  # 1.5: SUMO copies vehicles (--scale), the warm-up runs in place
        env.reset(seed=0, options={"traffic_level": level})
        assert env.sumo.simulation.getTime() == 25200 + 60 + 1


def test_sumo_changes_lanes_to_follow_the_route(
    make_env: Callable[..., UrbanDriveEnv], netgen: Callable[..., Path]
) -> None:
    net = netgen("grid", *GRID_WITH_LIGHTS, "--default.lanenumber", "2")
    env = make_env(net_file=net, route=("A0B0", "D3D4"), max_steps=300, warmup_s=0)
    obs, _ = env.reset(seed=0)
    driver, lanes = CautiousDriver(), set()
    for _ in range(300):
        obs, _r, terminated, truncated, info = env.step(driver(obs))
        if terminated or truncated:
            break
        lanes.add(env.sumo.vehicle.getLaneID("ego"))
    # straight on in the left lane of B2B3, then over to its right lane for the right turn
    assert {"B2B3_0", "B2B3_1"} <= lanes
    assert info["arrived"] and not info["collision"]
