"""The SUMO process of an episode, against a live SUMO (libsumo)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import traci.constants as tc

from explaindrive.env.sumo_process import SUMO_DRIVES, SumoProcess
from explaindrive.sim.route import load_route_geometry
from explaindrive.sim.scenario.source import ScenarioSource


@pytest.fixture
def process(make_env: Any) -> Iterator[SumoProcess]:
    make_env()  # closes the other tests' simulations (libsumo: one per process)
    proc = SumoProcess(gui=False, ego_model="agent", insert_timeout_s=60)
    yield proc
    proc.close()


def test_the_ego_enters_and_moves_at_the_speed_it_is_given(
    process: SumoProcess, tmp_path: Any
) -> None:
    scenario = ScenarioSource(tmp_path).current
    crossings = load_route_geometry(scenario.net_file, scenario.route_edges).crossings
    entry = process.start_episode(scenario, crossings, 0.5, 3, 60, drop_backlog=False)
    assert entry.length_m == 5.0 and entry.min_gap_m == 2.5  # the ego vType
    assert process.api.simulation.getTime() == 61.0  # 60 s of warm-up, one to enter
    calls: list[float] = []
    motion = process.advance(3.0, 3.0, lambda api: calls.append(api.simulation.getTime()))
    assert calls == [61.0]  # before the step
    assert motion.speed_mps == 3.0 and not motion.collided and not motion.arrived
    assert process.ego_state()[tc.VAR_SPEED] == 3.0
    motion = process.advance(SUMO_DRIVES, 0.0, lambda api: None)
    assert motion.speed_mps > 3.0  # SUMO accelerates the ego itself
