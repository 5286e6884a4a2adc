"""The kerb rule of the zebra against a recording stand-in for SUMO's person API."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from explaindrive.sim.pedestrians import KerbYield
from explaindrive.sim.route import RouteCrossing

ZEBRA = RouteCrossing(":PX_c0", (":PX_w0", ":PX_w1"), stop_line_m=100.0, signalized=False,
                      end_m=107.0)  # fmt: skip
SIGNAL = RouteCrossing(":J2_c0", (":J2_w0",), stop_line_m=100.0, signalized=True, end_m=110.0)


class FakeSumo:
    """Persons on edges with their next edge and walking speed; records speed changes."""

    def __init__(self, persons: dict[str, tuple[str, str, float]]) -> None:
        self.persons = persons  # id -> (edge, next edge, max speed)
        self.set_speeds: list[tuple[str, float]] = []
        self.edge = SimpleNamespace(getLastStepPersonIDs=self._on_edge)
        self.person = SimpleNamespace(
            getNextEdge=lambda pid: self.persons[pid][1],
            getMaxSpeed=lambda pid: self.persons[pid][2],
            setSpeed=self._set_speed,
            getIDList=lambda: tuple(self.persons),
        )

    def _on_edge(self, edge: str) -> list[str]:
        return [pid for pid, (on, _, _) in self.persons.items() if on == edge]

    def _set_speed(self, pid: str, speed: float) -> None:
        edge, nxt, _ = self.persons[pid]
        self.persons[pid] = (edge, nxt, speed)
        self.set_speeds.append((pid, speed))


def sumo() -> FakeSumo:
    return FakeSumo({
        "about_to_cross": (":PX_w1", ":PX_c0", 1.4),
        "leaving": (":PX_w0", "PX_PXN", 1.3),  # came off the crossing: not held
        "on_crossing": (":PX_c0", ":PX_w0", 1.2),  # already walking: not held
    })  # fmt: skip


@pytest.mark.parametrize(
    ("front", "reach", "held"),
    [
        (95.0, 7.0, True),  # 5 m before the line, needs 7 m to stand still
        (90.0, 7.0, False),  # 10 m before: can stop, so the pedestrian walks
        (99.5, 0.0, False),  # standing 0.5 m before the line: the pedestrian walks
        (101.0, 0.0, False),  # standing on the crossing: the pedestrian passes it
        (101.0, 2.0, True),  # moving on the crossing
        (111.0, 9.0, True),  # front beyond, rear (111 - 5 = 106) still on it
        (112.0, 9.0, False),  # rear at the junction's end: clear
    ],
)
def test_who_waits(front: float, reach: float, held: bool) -> None:
    api, kerb = sumo(), KerbYield()
    kerb.update(api, (ZEBRA,), front_m=front, length_m=5.0, reach_m=reach)
    assert kerb.holds("about_to_cross") is held
    assert not kerb.holds("leaving") and not kerb.holds("on_crossing")
    assert api.set_speeds == ([("about_to_cross", 0.0)] if held else [])


def test_released_pedestrian_walks_at_its_own_speed() -> None:
    api, kerb = sumo(), KerbYield()
    kerb.update(api, (ZEBRA,), front_m=95.0, length_m=5.0, reach_m=7.0)
    kerb.update(api, (ZEBRA,), front_m=97.0, length_m=5.0, reach_m=7.0)  # still held
    kerb.update(api, (ZEBRA,), front_m=112.0, length_m=5.0, reach_m=9.0)  # the car is past
    assert not kerb.holds("about_to_cross")
    assert api.set_speeds == [("about_to_cross", 0.0), ("about_to_cross", 1.4)]


def test_a_person_gone_while_held_is_forgotten() -> None:
    api, kerb = sumo(), KerbYield()
    kerb.update(api, (ZEBRA,), front_m=95.0, length_m=5.0, reach_m=7.0)
    del api.persons["about_to_cross"]
    kerb.update(api, (ZEBRA,), front_m=112.0, length_m=5.0, reach_m=9.0)
    assert not kerb.holds("about_to_cross")
    assert api.set_speeds == [("about_to_cross", 0.0)]


def test_signalized_crossings_are_left_to_their_lights() -> None:
    api = FakeSumo({"waiting": (":J2_w0", ":J2_c0", 1.4)})
    kerb = KerbYield()
    kerb.update(api, (SIGNAL,), front_m=101.0, length_m=5.0, reach_m=0.0)
    assert not kerb.holds("waiting") and api.set_speeds == []
