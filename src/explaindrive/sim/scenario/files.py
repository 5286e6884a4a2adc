"""Files of a scenario: the committed network and the demand generated per traffic level."""

from __future__ import annotations

import hashlib
import os
import tempfile
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from xml.sax.saxutils import quoteattr

from explaindrive.cache import cache_dir as user_cache_dir
from explaindrive.sim.scenario import layout

EGO_ROUTE_ID = "ego_route"
EGO_TYPE_ID = "ego_type"
EGO_ID = "ego"
# vTypes of the ego when SUMO drives it (baselines): same size and limits as the agent's ego.
BASELINE_EGO_TYPES: dict[str, str] = {"krauss": "ego_krauss", "idm": "ego_idm"}
FLOW_END_S = 4_000  # [s] flows outlast warm-up plus the longest episode


def package_data_dir() -> Path:
    """Directory of the committed scenario files inside the package."""
    return Path(str(resources.files("explaindrive.sim.scenario") / "data"))


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def routes_xml(traffic_level: float) -> str:
    """Vehicle demand at a traffic level: flows with Poisson arrivals and the ego route.

    Flows scale with the level; level 1.0 puts 900 veh/h on the ego's main road.
    Pedestrians are added by :class:`explaindrive.sim.pedestrians.PedestrianSource`.
    """
    level = layout.validate_traffic_level(traffic_level)
    lines = ["<routes>"]
    lines.append(
        f'    <vType id="{EGO_TYPE_ID}" length="5" minGap="2.5" maxSpeed="20" accel="3" '
        'decel="3" emergencyDecel="9" color="1,0,0" guiShape="passenger"/>'
    )
    for model, type_id in BASELINE_EGO_TYPES.items():
        cf = "Krauss" if model == "krauss" else "IDM"
        lines.append(
            f'    <vType id="{type_id}" length="5" minGap="2.5" maxSpeed="20" accel="3" '
            f'decel="3" emergencyDecel="9" speedFactor="1" speedDev="0" '
            f'carFollowModel="{cf}" color="0,0,1"/>'
        )
    lines.append(
        '    <vType id="background" length="5" minGap="2.5" maxSpeed="20" accel="2.6" '
        'decel="4.5" sigma="0.5" carFollowModel="Krauss" color="0.8,0.8,0.2"/>'
    )
    lines.append(f'    <route id="{EGO_ROUTE_ID}" edges="{" ".join(layout.EGO_ROUTE_EDGES)}"/>')
    for flow in layout.FLOWS:
        rate = flow.veh_per_hour * level / 3600.0  # [veh/s]
        attrs = {
            "id": flow.id,
            "type": "background",
            "begin": "0",
            "end": str(FLOW_END_S),
            "period": f"exp({_fmt(rate)})",
            "departLane": "best",
            "departSpeed": "max",
            "departPos": "base",
        }
        attr_text = " ".join(f"{k}={quoteattr(v)}" for k, v in attrs.items())
        lines.append(f"    <flow {attr_text}>")
        lines.append(f'        <route edges="{" ".join(flow.edges)}"/>')
        lines.append("    </flow>")
    lines.append("</routes>")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True, slots=True)
class ScenarioFiles:
    """Locations of a scenario's network and of its generated files."""

    net_file: Path
    cache_dir: Path

    def check(self) -> None:
        """Raise ``FileNotFoundError`` with a clear message if the network is missing."""
        if not self.net_file.is_file():
            raise FileNotFoundError(
                f"SUMO network file not found: {self.net_file} "
                "(rebuild it with `explaindrive scenario build`)"
            )

    @property
    def net_digest(self) -> str:
        """Short content hash of the network, used to key cached files."""
        digest = hashlib.sha1(self.net_file.read_bytes()).hexdigest()
        return digest[:10]

    def routes_file(self, traffic_level: float) -> Path:
        """Demand file for a traffic level, written on first use (atomically)."""
        text = routes_xml(traffic_level)
        key = hashlib.sha1(text.encode()).hexdigest()[:10]
        path = self.cache_dir / "routes" / f"level{traffic_level:g}_{key}.rou.xml"
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
            with os.fdopen(fd, "w") as fh:
                fh.write(text)
            os.replace(tmp, path)
        return path

    def state_dir(self) -> Path:
        """Directory of cached warm-up states."""
        return self.cache_dir / "states" / self.net_digest


def default_scenario(cache_dir: Path | None = None) -> ScenarioFiles:
    """The shipped urban scenario."""
    return ScenarioFiles(
        net_file=package_data_dir() / "urban.net.xml",
        cache_dir=cache_dir or user_cache_dir(),
    )
