"""Figure of the network, drawn from the network file with sumolib and matplotlib."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from explaindrive.sim.route import read_net
from explaindrive.sim.scenario.layout import EGO_ROUTE_EDGES, KMH


def plot_network(net_file: Path, out_file: Path) -> Path:
    """Render lanes (ego route by speed zone), lights, crossings and sidewalks to a PNG."""
    net = read_net(net_file)
    fig, ax = plt.subplots(figsize=(14, 4.2))
    zone_colour = {50: "#1f77b4", 30: "#ff7f0e"}
    for edge in net.getEdges(withInternal=True):
        fn = edge.getFunction()
        for lane in edge.getLanes():
            xs, ys = zip(*lane.getShape(), strict=False)
            if fn == "crossing":
                ax.plot(xs, ys, color="k", lw=4, solid_capstyle="butt")
                ax.plot(xs, ys, color="w", lw=2.5, ls=(0, (1, 1)), solid_capstyle="butt")
            elif fn == "walkingarea":
                continue
            elif lane.allows("pedestrian") and not lane.allows("passenger"):
                ax.plot(xs, ys, color="#bbbbbb", lw=1)
            elif edge.getID() in EGO_ROUTE_EDGES:
                kmh = round(lane.getSpeed() / KMH)
                ax.plot(xs, ys, color=zone_colour.get(kmh, "#2ca02c"), lw=2.2)
            else:
                ax.plot(xs, ys, color="#555555", lw=1.2)
    for tls in net.getTrafficLights():
        for conn in tls.getConnections():
            x, y = conn[0].getShape()[-1]
            ax.plot(x, y, "o", color="red", ms=5)
    for node in net.getNodes():
        if node.getType() in ("traffic_light", "priority") and len(node.getIncoming()) > 2:
            x, y = node.getCoord()
            ax.annotate(node.getID(), (x, y), xytext=(x + 8, y + 18), fontsize=9)
    start = net.getEdge(EGO_ROUTE_EDGES[0]).getShape()[0]
    ax.annotate(
        "ego start",
        start,
        xytext=(start[0], start[1] - 25),
        fontsize=9,
        arrowprops={"arrowstyle": "->"},
    )
    handles = [
        plt.Line2D([], [], color=zone_colour[50], lw=2.2, label="ego route, 50 km/h"),
        plt.Line2D([], [], color=zone_colour[30], lw=2.2, label="ego route, 30 km/h"),
        plt.Line2D([], [], color="#555555", lw=1.2, label="side roads"),
        plt.Line2D([], [], color="#bbbbbb", lw=1, label="sidewalks / footpaths"),
        plt.Line2D([], [], color="k", lw=4, label="pedestrian crossing"),
        plt.Line2D([], [], color="red", marker="o", ls="", label="signal stop lines"),
    ]
    ax.legend(handles=handles, loc="upper right", fontsize=8, ncol=3)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("ExplainDrive urban scenario")
    fig.tight_layout()
    out_file.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out_file, dpi=130)
    plt.close(fig)
    return out_file
