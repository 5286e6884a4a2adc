"""Pedestrian arrivals: Poisson per flow, drawn as the ride goes."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from explaindrive.sim.pedestrians import PedestrianSource
from explaindrive.sim.scenario.layout import PedestrianFlow

FLOWS = (
    PedestrianFlow("north", "a", "b", 360.0, 1.0, 2.0),  # one every 10 s on average
    PedestrianFlow("south", "b", "a", 120.0, 1.0, 2.0),  # one every 30 s
    PedestrianFlow("closed", "c", "d", 0.0, 1.0, 2.0),  # nobody
)


def recorder() -> tuple[SimpleNamespace, list[str]]:
    added: list[str] = []
    person = SimpleNamespace(
        add=lambda pid, edge, pos, depart: added.append(pid),
        appendWalkingStage=lambda pid, edges, pos: None,
    )
    return SimpleNamespace(person=person), added


def test_arrivals_follow_each_flows_own_poisson_process():
    api, added = recorder()
    source = PedestrianSource(7, FLOWS)
    source.step(api, 36_000.0)  # ten hours
    north = sum(pid.startswith("ped_north") for pid in added)
    south = sum(pid.startswith("ped_south") for pid in added)
    assert abs(north - 3600) < 4 * np.sqrt(3600) and abs(south - 1200) < 4 * np.sqrt(1200)
    assert not any(pid.startswith("ped_closed") for pid in added)
    assert source.added == len(added)


def test_the_first_arrival_is_the_flows_first_draw():
    api, added = recorder()
    source = PedestrianSource(3, FLOWS)
    first_north = float(np.random.default_rng([3, 0]).exponential(10.0))
    first_south = float(np.random.default_rng([3, 1]).exponential(30.0))
    source.step(api, min(first_north, first_south) - 1e-9)
    assert added == []
    source.step(api, min(first_north, first_south))
    assert added == ["ped_north_0" if first_north < first_south else "ped_south_0"]


def test_the_same_seed_the_same_pedestrians_in_any_step_pattern():
    (api_a, a), (api_b, b) = recorder(), recorder()
    one, other = PedestrianSource(11, FLOWS), PedestrianSource(11, FLOWS)
    one.step(api_a, 600.0)
    for t in range(601):
        other.step(api_b, float(t))
    assert a == b


def test_nothing_is_drawn_ahead():
    source = PedestrianSource(5, FLOWS)
    source.step(recorder()[0], 1_000_000.0)
    assert len(source._due) == 2  # one pending arrival per open flow, however long the ride
