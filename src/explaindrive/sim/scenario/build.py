"""Build the urban network with SUMO's own tools.

Writes plain XML (nodes, edges, connections with crossings) of a
:class:`~explaindrive.sim.scenario.layout.Layout` (the paper's road by default) and runs
``netconvert`` on it. The paper's ``urban.net.xml`` is committed with the package, so
running it never needs ``netconvert``; rebuild it with ``explaindrive scenario build``.
"""

from __future__ import annotations

import logging
import subprocess
from pathlib import Path
from xml.sax.saxutils import quoteattr

from explaindrive.sim.scenario import layout
from explaindrive.sim.sumo_home import sumo_binary

log = logging.getLogger(__name__)

NODES_FILE = "urban.nod.xml"
EDGES_FILE = "urban.edg.xml"
CONNECTIONS_FILE = "urban.con.xml"
NET_FILE = "urban.net.xml"


def _attrs(**kwargs: object) -> str:
    return " ".join(f"{k}={quoteattr(str(v))}" for k, v in kwargs.items())


def nodes_xml(plan: layout.Layout = layout.PAPER_LAYOUT) -> str:
    """Plain node XML of the layout."""
    lines = ['<nodes version="1.20">']
    for n in plan.nodes:
        joined = {"tl": n.tl} if n.tl is not None else {}
        lines.append(f"    <node {_attrs(id=n.id, x=n.x, y=n.y, type=n.type, **joined)}/>")
    lines.append("</nodes>")
    return "\n".join(lines) + "\n"


def edges_xml(plan: layout.Layout = layout.PAPER_LAYOUT) -> str:
    """Plain edge XML: one edge per direction; streets get a vehicle lane and a sidewalk."""
    lines = ['<edges version="1.20">']
    for road in plan.roads:
        for eid, a, b in ((road.forward, road.a, road.b), (road.backward, road.b, road.a)):
            if road.kind == "footpath":
                attrs = _attrs(
                    id=eid,
                    **{"from": a},
                    to=b,
                    numLanes=1,
                    speed=f"{road.speed_mps:.4f}",
                    allow="pedestrian",
                    width=layout.SIDEWALK_WIDTH_M,
                )
            else:
                attrs = _attrs(
                    id=eid,
                    **{"from": a},
                    to=b,
                    numLanes=road.forward_lanes if eid == road.forward else 1,
                    speed=f"{road.speed_mps:.4f}",
                    priority=_priority(road),
                    sidewalkWidth=layout.SIDEWALK_WIDTH_M,
                )
            lines.append(f"    <edge {attrs}/>")
    lines.append("</edges>")
    return "\n".join(lines) + "\n"


def _priority(road: layout.Road) -> int:
    """netconvert's edge priority of ``road``: its own, else the main road's for a road
    starting on the ego's route and the side roads' for the others."""
    if road.priority is not None:
        return road.priority
    if road.a in layout.EGO_ROUTE_NODES:
        return layout.MAIN_ROAD_PRIORITY
    return layout.SIDE_ROAD_PRIORITY


def connections_xml(plan: layout.Layout = layout.PAPER_LAYOUT) -> str:
    """Plain connection XML: the lane connections the plan fixes (its lanes' arrows), then
    the pedestrian crossings."""
    lines = ['<connections version="1.20">']
    for c in plan.connections:
        attrs = _attrs(**{"from": c.from_edge}, to=c.to_edge, fromLane=c.from_lane,
                       toLane=c.to_lane)  # fmt: skip
        lines.append(f"    <connection {attrs}/>")
    for node, edges in plan.crossings:
        signalized = any(n.id == node and n.type == "traffic_light" for n in plan.nodes)
        attrs = _attrs(
            node=node,
            edges=" ".join(edges),
            priority="true",
            width=4.0,
        )
        note = "signalized" if signalized else "zebra"
        lines.append(f"    <crossing {attrs}/> <!-- {note} -->")
    lines.append("</connections>")
    return "\n".join(lines) + "\n"


def write_plain_xml(out_dir: Path, plan: layout.Layout = layout.PAPER_LAYOUT) -> dict[str, Path]:
    """Write the plain node/edge/connection files into ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    files = {
        "nodes": out_dir / NODES_FILE,
        "edges": out_dir / EDGES_FILE,
        "connections": out_dir / CONNECTIONS_FILE,
    }
    files["nodes"].write_text(nodes_xml(plan))
    files["edges"].write_text(edges_xml(plan))
    files["connections"].write_text(connections_xml(plan))
    return files


def netconvert_args(files: dict[str, Path], net_file: Path) -> list[str]:
    """Command line for netconvert."""
    return [
        sumo_binary("netconvert"),
        "--node-files",
        str(files["nodes"]),
        "--edge-files",
        str(files["edges"]),
        "--connection-files",
        str(files["connections"]),
        "--output-file",
        str(net_file),
        "--no-turnarounds",
        "true",
        "--tls.default-type",
        "static",
        "--tls.cycle.time",
        str(layout.TLS_CYCLE_S),
        "--tls.yellow.time",
        str(layout.TLS_YELLOW_S),
        "--tls.allred.time",
        str(layout.TLS_ALL_RED_S),
        "--tls.left-green.time",
        "0",
        "--walkingareas",
        "true",
        "--junctions.corner-detail",
        "5",
        "--no-warnings",
        "true",
        "--output.street-names",
        "false",
    ]


def build_network(out_dir: Path, plan: layout.Layout = layout.PAPER_LAYOUT) -> Path:
    """Write the plain XML of ``plan`` and run netconvert; returns the network file.

    Raises:
        RuntimeError: if netconvert fails (its stderr is included).
    """
    files = write_plain_xml(out_dir, plan)
    net_file = out_dir / NET_FILE
    args = netconvert_args(files, net_file)
    log.info("running %s", " ".join(args))
    proc = subprocess.run(args, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"netconvert failed ({proc.returncode}):\n{proc.stderr}")
    for tls_id in plan.joined_tls:
        _merge_side_streams(net_file, tls_id)
    for tls_id, offset_s in plan.tls_offsets_s.items():
        _apply_offset(net_file, tls_id, offset_s)
    for tls_id, durations in plan.tls_phase_durations_s.items():
        _apply_durations(net_file, tls_id, durations)
    return net_file


def _side_state(main: str, greens: list[str]) -> str:
    """The side roads' green of a joined programme: every link red in the main green
    ``main`` that one of the later ``greens`` lets go (``G`` before ``g``)."""
    chars = []
    for i, c in enumerate(main):
        own = [g[i] for g in greens if g[i] in "Gg"]
        chars.append("r" if c in "Gg" or not own else "G" if "G" in own else "g")
    return "".join(chars)


def _merge_side_streams(net_file: Path, tls_id: str) -> None:
    """Merge the side-road greens of a joined programme into one phase.

    netconvert gives a cluster of junctions on one light (``tl`` of the plain nodes) the
    main road's green, then a green for each junction's side roads, each followed by a
    yellow and an all-red. The family's lights have two streams (main road, side roads;
    :meth:`~explaindrive.sim.scenario.params.SignalParams.durations`), so the side greens
    become one: every side road of the cluster green at once, the main road red.

    Raises:
        RuntimeError: if the light is missing or its programme is not of that shape.
    """
    import re

    text = net_file.read_text()
    block = re.search(rf'<tlLogic id="{tls_id}".*?</tlLogic>', text, flags=re.S)
    if block is None:
        raise RuntimeError(f"traffic light {tls_id!r} not found in {net_file}")
    states = re.findall(r'state="([^"]+)"', block.group(0))
    if len(states) % 3 or len(states) < 6:
        raise RuntimeError(f"traffic light {tls_id!r}: {len(states)} phases, not green, "
                           "yellow and all-red per stream")  # fmt: skip
    main, side = states[0], _side_state(states[0], states[3::3])
    red = "r" * len(main)
    phases = (main, states[1], red, side, re.sub("[Gg]", "y", side), red)
    head = block.group(0).split("\n", 1)[0]
    lines = [f'        <phase duration="1" state="{state}"/>' for state in phases]
    net_file.write_text(text.replace(block.group(0), "\n".join([head, *lines, "    </tlLogic>"])))


def _apply_durations(net_file: Path, tls_id: str, durations: tuple[int, ...]) -> None:
    """Set the phase durations of one static program in the generated network."""
    import re

    text = net_file.read_text()
    block = re.search(rf'<tlLogic id="{tls_id}".*?</tlLogic>', text, flags=re.S)
    if block is None:
        raise RuntimeError(f"traffic light {tls_id!r} not found in {net_file}")
    phases = re.findall(r'<phase duration="\d+"\s*', block.group(0))
    if len(phases) != len(durations):
        raise RuntimeError(
            f"traffic light {tls_id!r} has {len(phases)} phases, layout gives {len(durations)}"
        )
    it = iter(durations)
    new_block = re.sub(
        r'<phase duration="\d+"\s*', lambda _m: f'<phase duration="{next(it)}" ', block.group(0)
    )
    net_file.write_text(text.replace(block.group(0), new_block))


def _apply_offset(net_file: Path, tls_id: str, offset_s: int) -> None:
    """Set the offset of one static program in the generated network."""
    text = net_file.read_text()
    marker = f'<tlLogic id="{tls_id}" type="static" programID="0" offset="0">'
    if marker not in text:
        raise RuntimeError(f"traffic light {tls_id!r} not found in {net_file}")
    net_file.write_text(text.replace(marker, marker.replace('offset="0"', f'offset="{offset_s}"')))
