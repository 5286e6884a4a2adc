"""A stand-in for the parts of libsumo the perception and violation modules read."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import traci.constants as tc


class FakeSumo:
    """Vehicles, lights, pedestrians and collisions set by the test.

    Args:
        vehicles: id -> (length_m, speed_mps).
        lights: tls id -> its red-yellow-green state string.
        persons: edge -> person ids on it.
        people: person id -> (x, y, angle_deg, speed_mps, next_edge).
        collisions: (collider, victim) pairs of this step.
        links: the ego's signalled links, (tls id, link index, gap [m], state), nearest first.
    """

    def __init__(
        self,
        vehicles: dict[str, tuple[float, float]] | None = None,
        lights: dict[str, str] | None = None,
        persons: dict[str, tuple[str, ...]] | None = None,
        people: dict[str, tuple[float, float, float, float, str]] | None = None,
        collisions: tuple[tuple[str, str], ...] = (),
        links: tuple[tuple[str, int, float, str], ...] = (),
    ) -> None:
        self.length_reads = 0
        vehicles, lights, persons, people = (
            vehicles or {},
            lights or {},
            persons or {},
            people or {},
        )

        def length(vid: str) -> float:
            self.length_reads += 1
            return vehicles[vid][0]

        self.vehicle = SimpleNamespace(
            getLength=length, getSpeed=lambda v: vehicles[v][1], getNextTLS=lambda v: links
        )
        self.trafficlight = SimpleNamespace(getRedYellowGreenState=lambda t: lights[t])
        self.edge = SimpleNamespace(
            getSubscriptionResults=lambda e: {tc.LAST_STEP_PERSON_ID_LIST: persons.get(e, ())}
        )
        self.person = SimpleNamespace(
            getPosition=lambda p: people[p][:2],
            getAngle=lambda p: people[p][2],
            getSpeed=lambda p: people[p][3],
            getNextEdge=lambda p: people[p][4],
        )
        self.simulation = SimpleNamespace(
            getCollisions=lambda: [SimpleNamespace(collider=a, victim=b) for a, b in collisions]
        )


def ego_results(
    speed_mps: float, leader: tuple[str, float] | None = None, lane: str | None = None
) -> dict[int, Any]:
    """The ego's subscription results."""
    out: dict[int, Any] = {tc.VAR_SPEED: speed_mps, tc.VAR_LEADER: leader or ("", -1.0)}
    if lane is not None:
        out[tc.VAR_LANE_ID] = lane
    return out
