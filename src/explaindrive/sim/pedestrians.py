"""Pedestrian demand, generated from Python so that it survives SUMO state loading.

SUMO does not restore person flows from a saved state, so the environment adds
pedestrians itself: Poisson arrivals per flow, drawn from a generator seeded
with the episode seed (the same seed gives the same pedestrians).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from explaindrive.sim.scenario.layout import PEDESTRIAN_FLOWS, PedestrianFlow


class PedestrianSource:
    """Adds the pedestrians of :data:`PEDESTRIAN_FLOWS` to a running simulation.

    Args:
        seed: seed of the arrival process.
        horizon_s: arrivals are drawn for this many seconds.
        flows: the pedestrian flows (the scenario's by default).
    """

    def __init__(
        self, seed: int, horizon_s: float, flows: tuple[PedestrianFlow, ...] = PEDESTRIAN_FLOWS
    ) -> None:
        rng = np.random.default_rng(seed)
        arrivals: list[tuple[float, int]] = []
        for i, flow in enumerate(flows):
            mean_gap_s = 3600.0 / flow.persons_per_hour
            t = float(rng.exponential(mean_gap_s))
            while t < horizon_s:
                arrivals.append((t, i))
                t += float(rng.exponential(mean_gap_s))
        arrivals.sort()
        self._arrivals = arrivals
        self._flows = flows
        self._next = 0
        self._count = 0

    @property
    def added(self) -> int:
        """Pedestrians added so far."""
        return self._count

    def step(self, api: Any, elapsed_s: float) -> None:
        """Add every pedestrian due by ``elapsed_s`` (seconds since the source started)."""
        while self._next < len(self._arrivals) and self._arrivals[self._next][0] <= elapsed_s:
            flow = self._flows[self._arrivals[self._next][1]]
            pid = f"ped_{flow.id}_{self._count}"
            api.person.add(pid, flow.from_edge, flow.depart_pos_m, depart=-3)
            api.person.appendWalkingStage(pid, [flow.from_edge, flow.to_edge], flow.arrival_pos_m)
            self._next += 1
            self._count += 1
