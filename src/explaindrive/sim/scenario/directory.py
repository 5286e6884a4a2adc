"""A scenario directory: ``scenario.yaml``, the built network and its demand at level 1.0.

``scenario.yaml`` holds the scenario's name, the generator seed if it was drawn, and every
parameter (:class:`~explaindrive.sim.scenario.params.ScenarioParams`). The network is built
once, when the directory is written; loading it runs no SUMO tool. Generated scenarios are
cached by their parameters under the cache directory, so drawing one again is free.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import yaml

from explaindrive.config import ConfigError, read_yaml
from explaindrive.sim.scenario.build import NET_FILE, build_network
from explaindrive.sim.scenario.files import ScenarioFiles, routes_xml
from explaindrive.sim.scenario.layout import make_layout
from explaindrive.sim.scenario.params import ScenarioParams

SCENARIO_FILE = "scenario.yaml"
DEMAND_FILE = "urban.rou.xml"  # the demand at traffic level 1.0, for SUMO's own tools


class ScenarioDirError(ValueError):
    """A scenario directory that cannot be read; the message names why."""


def write_scenario_dir(
    out: Path, params: ScenarioParams, name: str, seed: int | None = None
) -> Path:
    """Build the network of ``params`` into ``out`` and write its demand and ``scenario.yaml``.

    Raises:
        RuntimeError: if netconvert fails.
    """
    plan = make_layout(params)
    build_network(out, plan)
    (out / DEMAND_FILE).write_text(routes_xml(1.0, plan, plan.route_edges))
    doc: dict[str, Any] = {"name": name}
    if seed is not None:
        doc["seed"] = seed
    doc["params"] = params.to_dict()
    (out / SCENARIO_FILE).write_text(yaml.safe_dump(doc, sort_keys=False))
    return out


def read_params(directory: Path) -> tuple[str, ScenarioParams]:
    """The name and parameters in a scenario directory.

    Raises:
        ScenarioDirError: if the directory, its ``scenario.yaml`` or its network is missing,
            or the parameters are invalid.
    """
    path = directory / SCENARIO_FILE
    if not directory.is_dir():
        raise ScenarioDirError(f"scenario directory not found: {directory}")
    if not path.is_file() or not (directory / NET_FILE).is_file():
        raise ScenarioDirError(
            f"{directory} is not a scenario directory (it needs {SCENARIO_FILE} and {NET_FILE}; "
            "write one with `explaindrive scenario build --out DIR`)"
        )
    try:
        doc = read_yaml(path.read_text(encoding="utf-8"))
        if not isinstance(doc, dict) or not isinstance(doc.get("params"), dict):
            raise ScenarioDirError(f"{path} has no 'params' mapping")
        return str(doc.get("name", directory.name)), ScenarioParams.from_dict(doc["params"])
    except (yaml.YAMLError, ConfigError) as exc:
        raise ScenarioDirError(f"{path}: {exc}") from None


def load_scenario_dir(directory: Path, cache_dir: Path) -> ScenarioFiles:
    """The scenario in a directory written by :func:`write_scenario_dir`.

    Raises:
        ScenarioDirError: as :func:`read_params`.
    """
    name, params = read_params(directory)
    plan = make_layout(params)
    return ScenarioFiles(net_file=directory / NET_FILE, cache_dir=cache_dir,
                         route_edges=plan.route_edges, plan=plan, name=name)  # fmt: skip


def cached_scenario_dir(params: ScenarioParams, name: str, cache_dir: Path,
                        seed: int | None = None) -> Path:  # fmt: skip
    """The directory of ``params`` in the cache, written (with netconvert) on first use."""
    key = hashlib.sha1(json.dumps(params.to_dict(), sort_keys=True).encode()).hexdigest()[:12]
    out = cache_dir / "scenarios" / key
    if (out / SCENARIO_FILE).is_file():
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=out.parent, prefix=".build-"))
    try:
        write_scenario_dir(tmp, params, name, seed)
        os.replace(tmp, out)
    except OSError:  # another process built it first
        if not (out / SCENARIO_FILE).is_file():
            raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return out


def random_scenario(seed: int, cache_dir: Path) -> ScenarioFiles:
    """Generated scenario ``seed``, built into the cache on first use."""
    from explaindrive.sim.scenario.generator import random_params

    name = f"random-{seed}"
    return load_scenario_dir(cached_scenario_dir(random_params(seed), name, cache_dir, seed),
                             cache_dir)  # fmt: skip
