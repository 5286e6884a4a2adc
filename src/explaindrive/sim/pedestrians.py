"""Pedestrians: their demand, and the rule that keeps them off a crossing the ego is on.

SUMO does not restore person flows from a saved state, so the environment adds
pedestrians itself: Poisson arrivals per flow, drawn as the ride goes from a generator
seeded with the episode seed (the same seed gives the same pedestrians).
"""

from __future__ import annotations

import heapq
from typing import Any

import numpy as np

from explaindrive.sim.route import RouteCrossing
from explaindrive.sim.scenario.layout import PEDESTRIAN_FLOWS, PedestrianFlow


class PedestrianSource:
    """Adds the pedestrians of :data:`PEDESTRIAN_FLOWS` to a running simulation.

    Each flow is a Poisson process with a generator of its own, seeded with the episode seed
    and the flow's index; the next arrival of a flow is drawn only once the previous one has
    been added, so memory does not grow with the length of a ride.

    Args:
        seed: seed of the arrival processes.
        flows: the pedestrian flows (the scenario's by default).
    """

    def __init__(self, seed: int, flows: tuple[PedestrianFlow, ...] = PEDESTRIAN_FLOWS) -> None:
        self._flows = flows
        self._rngs = [np.random.default_rng([seed, i]) for i in range(len(flows))]
        self._due: list[tuple[float, int]] = [
            (self._gap(i), i) for i in range(len(flows)) if flows[i].persons_per_hour > 0
        ]
        heapq.heapify(self._due)
        self._count = 0

    def _gap(self, flow: int) -> float:
        return float(self._rngs[flow].exponential(3600.0 / self._flows[flow].persons_per_hour))

    @property
    def added(self) -> int:
        """Pedestrians added so far."""
        return self._count

    def step(self, api: Any, elapsed_s: float) -> None:
        """Add every pedestrian due by ``elapsed_s`` (seconds since the source started)."""
        while self._due and self._due[0][0] <= elapsed_s:
            t, i = heapq.heappop(self._due)
            flow = self._flows[i]
            pid = f"ped_{flow.id}_{self._count}"
            api.person.add(pid, flow.from_edge, flow.depart_pos_m, depart=-3)
            api.person.appendWalkingStage(pid, [flow.from_edge, flow.to_edge], flow.arrival_pos_m)
            self._count += 1
            heapq.heappush(self._due, (t + self._gap(i), i))


class KerbYield:
    """Pedestrians at a zebra wait on the kerb for a car that can no longer stop before the
    crossing or is already on it.

    SUMO's pedestrians step onto a crossing where they have priority whatever the
    approaching cars do. Traffic codes also bind pedestrians: none may step out in front of
    a vehicle so close that it cannot yield (e.g. the US Uniform Vehicle Code 11-502(b)).
    This class applies that rule to the ego: each step, the pedestrians about to step from
    a walking area onto an unsignalized crossing stand still while the ego moves on the
    crossing or would need more than the distance left to stand still before its stop line;
    they walk on at their own speed once it no longer holds. A car standing on the crossing
    does not hold them: they pass it, and a car that waits for them (as SUMO's drivers do)
    is not left waiting for pedestrians who wait for it.
    """

    def __init__(self) -> None:
        self._held: dict[str, float] = {}  # person -> its walking speed before the hold [m/s]

    def holds(self, person_id: str) -> bool:
        """Whether the person is waiting for the ego."""
        return person_id in self._held

    def update(
        self,
        api: Any,
        crossings: tuple[RouteCrossing, ...],
        front_m: float,
        length_m: float,
        reach_m: float,
    ) -> None:
        """Hold or release the pedestrians at the ego's crossings.

        Args:
            api: the running simulation (libsumo or traci).
            crossings: the crossings over the ego's route.
            front_m: route position of the ego's front [m].
            length_m: the ego's length [m].
            reach_m: how far the ego's front travels before it can stand still [m]; 0 for a
                car that stands still.
        """
        wanted = set()
        for crossing in crossings:
            if not crossing.signalized and _blocks(crossing, front_m, length_m, reach_m):
                wanted.update(_entering(api, crossing))
        if not wanted and not self._held:
            return
        person = api.person
        for pid in wanted.difference(self._held):
            self._held[pid] = float(person.getMaxSpeed(pid))
            person.setSpeed(pid, 0.0)
        released = [pid for pid in self._held if pid not in wanted]
        if released:
            present = set(person.getIDList())
            for pid in released:
                speed = self._held.pop(pid)
                if pid in present:
                    person.setSpeed(pid, speed)


def _blocks(crossing: RouteCrossing, front_m: float, length_m: float, reach_m: float) -> bool:
    """The ego moves on the crossing, or approaches it and cannot stand still before it
    (``reach_m`` is 0 for a car that stands still)."""
    if front_m - length_m >= crossing.end_m or reach_m <= 0.0:
        return False
    ahead = crossing.stop_line_m - front_m
    return ahead < reach_m


def _entering(api: Any, crossing: RouteCrossing) -> list[str]:
    """The pedestrians on the crossing's walking areas whose next edge is the crossing."""
    person = api.person
    return [
        pid
        for wa in crossing.walkingareas
        for pid in api.edge.getLastStepPersonIDs(wa)
        if person.getNextEdge(pid) == crossing.crossing_edge
    ]
