"""What a top-down view draws: the road network once, then SUMO positions around the ego each
step. The passenger page (:mod:`explaindrive.web`) and the environment's ``rgb_array``
rendering (:mod:`explaindrive.env.render`) both draw from it.

Coordinates are SUMO's network coordinates [m] (x east, y north); angles are
SUMO's headings [deg] (0 = north, clockwise). A vehicle's position is the
middle of its front bumper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from explaindrive.sim.route import read_net
from explaindrive.sim.scenario.files import EGO_ID

VIEW_RADIUS_M = 150.0  # [m] objects farther from the ego are not streamed

# SUMO signal characters -> the colour a passenger sees.
_SIGNAL_COLOUR = {
    "G": "green",
    "g": "green",
    "y": "yellow",
    "Y": "yellow",
    "r": "red",
    "R": "red",
    "u": "yellow",
    "o": "off",
    "O": "off",
    "s": "green",
}


@dataclass(frozen=True, slots=True)
class SignalHead:
    """The signal a driver on one incoming lane sees at the stop line.

    Attributes:
        tls_id: traffic light id.
        link_index: index of the lane's straight-on link in the light's state string.
        x: stop-line position x [m].
        y: stop-line position y [m].
    """

    tls_id: str
    link_index: int
    x: float
    y: float


@dataclass(frozen=True)
class Scene:
    """Static geometry of the network, in the shape the page draws it.

    Attributes:
        lanes: drawable lanes: ``{"id", "kind" (road|sidewalk|internal), "width", "shape"}``.
        crossings: pedestrian crossings: ``{"id", "width", "shape"}``.
        signals: one signal head per signalised incoming road lane.
        bounds: ``[xmin, ymin, xmax, ymax]`` of the network [m].
    """

    lanes: list[dict[str, Any]]
    crossings: list[dict[str, Any]]
    signals: list[SignalHead]
    bounds: list[float]

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dict (signal heads without their link indices)."""
        return {
            "lanes": self.lanes,
            "crossings": self.crossings,
            "signals": [{"tls": s.tls_id, "x": s.x, "y": s.y} for s in self.signals],
            "bounds": self.bounds,
        }


def _shape(points: list[tuple[float, float]]) -> list[list[float]]:
    return [[round(x, 2), round(y, 2)] for x, y in points]


def load_scene(net_file: Path) -> Scene:
    """Read lanes, crossings and signal heads from a SUMO network file.

    Args:
        net_file: the ``.net.xml`` the ride simulates.

    Raises:
        FileNotFoundError: if the network file does not exist.
    """
    if not net_file.is_file():
        raise FileNotFoundError(f"SUMO network file not found: {net_file}")
    net = read_net(net_file)
    lanes: list[dict[str, Any]] = []
    crossings: list[dict[str, Any]] = []
    for edge in net.getEdges(withInternal=True):
        fn = edge.getFunction()
        if fn == "walkingarea":
            continue
        for lane in edge.getLanes():
            shape = _shape(lane.getShape())
            if fn == "crossing":
                crossings.append({"id": lane.getID(), "width": lane.getWidth(), "shape": shape})
                continue
            pedestrian_only = lane.allows("pedestrian") and not lane.allows("passenger")
            kind = "sidewalk" if pedestrian_only else ("internal" if fn == "internal" else "road")
            lanes.append(
                {"id": lane.getID(), "kind": kind, "width": lane.getWidth(), "shape": shape}
            )
    signals: list[SignalHead] = []
    for tls in net.getTrafficLights():
        by_lane: dict[str, tuple[int, bool]] = {}
        for conn in tls.getConnections():
            in_lane, _out_lane, index = conn[0], conn[1], int(conn[2])
            if in_lane.getEdge().getFunction() != "" or not in_lane.allows("passenger"):
                continue
            straight = any(
                c.getTLLinkIndex() == index and c.getDirection() == "s"
                for c in in_lane.getOutgoing()
            )
            held = by_lane.get(in_lane.getID())
            if held is None or (straight and not held[1]):
                by_lane[in_lane.getID()] = (index, straight)
        for lane_id, (index, _) in sorted(by_lane.items()):
            x, y = net.getLane(lane_id).getShape()[-1]
            signals.append(SignalHead(tls.getID(), index, round(x, 2), round(y, 2)))
    (xmin, ymin), (xmax, ymax) = net.getBBoxXY()
    return Scene(lanes, crossings, signals, [xmin, ymin, xmax, ymax])


def signal_colour(state: str, index: int) -> str:
    """The colour of link ``index`` in a SUMO red-yellow-green state string."""
    if not 0 <= index < len(state):
        return "off"
    return _SIGNAL_COLOUR.get(state[index], "off")


def snapshot(sumo: Any, scene: Scene, radius_m: float = VIEW_RADIUS_M) -> dict[str, Any]:
    """Positions around the ego from the running simulation.

    Args:
        sumo: the live ``libsumo``/``traci`` module.
        scene: the static scene (for the signal heads).
        radius_m: objects farther than this from the ego are left out [m].

    Returns:
        ``{"ego", "vehicles", "persons", "signals"}``; ``ego`` is ``None`` once the ego
        has left the network.
    """
    ids = set(sumo.vehicle.getIDList())
    ego = _vehicle(sumo, EGO_ID) if EGO_ID in ids else None
    cx, cy = (ego["x"], ego["y"]) if ego else (math.nan, math.nan)

    def near(x: float, y: float) -> bool:
        return ego is None or math.hypot(x - cx, y - cy) <= radius_m

    vehicles = []
    for vid in sorted(ids - {EGO_ID}):
        v = _vehicle(sumo, vid)
        if near(v["x"], v["y"]):
            vehicles.append(v)
    persons = []
    for pid in sorted(sumo.person.getIDList()):
        x, y = sumo.person.getPosition(pid)
        if near(x, y):
            persons.append(
                {"id": pid, "x": round(x, 2), "y": round(y, 2), "angle": sumo.person.getAngle(pid)}
            )
    states: dict[str, str] = {}
    signals = []
    for head in scene.signals:
        if not near(head.x, head.y):
            continue
        if head.tls_id not in states:
            states[head.tls_id] = sumo.trafficlight.getRedYellowGreenState(head.tls_id)
        colour = signal_colour(states[head.tls_id], head.link_index)
        signals.append({"tls": head.tls_id, "x": head.x, "y": head.y, "colour": colour})
    return {"ego": ego, "vehicles": vehicles, "persons": persons, "signals": signals}


def _vehicle(sumo: Any, vid: str) -> dict[str, Any]:
    x, y = sumo.vehicle.getPosition(vid)
    return {
        "id": vid,
        "x": round(x, 2),
        "y": round(y, 2),
        "angle": round(sumo.vehicle.getAngle(vid), 1),
        "length": sumo.vehicle.getLength(vid),
        "width": sumo.vehicle.getWidth(vid),
        "speed_mps": round(sumo.vehicle.getSpeed(vid), 2),
    }
