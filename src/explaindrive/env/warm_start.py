"""SUMO's options for an episode and the cached warm-up states episodes start from.

Every ``(scenario demand, traffic level, seed, warm-up)`` has a warm-up: traffic without
the ego from the demand's start, simulated once in a fresh ``sumo`` process and saved as a
SUMO state in the cache. A reset loads that state, so it costs a state load, not a
re-simulation, and the same seed gives the same episode.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
from pathlib import Path
from typing import Any

from explaindrive.env.actions import STEP_LENGTH_S
from explaindrive.sim.scenario.files import ScenarioFiles
from explaindrive.sim.sumo_home import sumo_binary


def sumo_args(scenario: ScenarioFiles, level: float, seed: int) -> list[str]:
    """SUMO's options (no binary) for an episode of ``scenario`` at a traffic level."""
    return [
        "-n",
        str(scenario.net_file),
        "-r",
        ",".join(str(p) for p in scenario.routes_files(level)),
        *scenario.demand_args(level),
        "--seed",
        str(seed),
        "--step-length",
        str(STEP_LENGTH_S),
        "--no-step-log",
        "true",
        "--no-warnings",
        "true",
        "--collision.action",
        "remove",
        "--collision.check-junctions",
        "true",
        "--collision.mingap-factor",
        "0",
        "--save-state.rng",
        "true",
        "--time-to-teleport",
        "-1",
    ]


def state_file(scenario: ScenarioFiles, level: float, seed: int, warmup_s: int) -> Path:
    """Where the warm-up state of (demand, level, seed, warm-up) is cached."""
    demand = scenario.demand_key(level)  # level + hash
    return scenario.state_dir() / f"{demand}_seed{seed}_warm{warmup_s}.xml"


def restore_warm_state(
    api: Any, scenario: ScenarioFiles, level: float, seed: int, warmup_s: int
) -> None:
    """Continue the running simulation from the cached warm-up state, creating it if needed;
    simulate the warm-up in place where SUMO cannot reload its state (a scaled-up demand).

    Raises:
        RuntimeError: if the warm-up fails or its state does not load.
    """
    if warmup_s == 0:
        return
    if not scenario.state_reloads(level):
        for _ in range(warmup_s):
            api.simulationStep()
        return
    path = state_file(scenario, level, seed, warmup_s)
    if not path.exists():
        write_warm_state(scenario, level, seed, warmup_s, path)
    try:
        api.simulation.loadState(str(path))
    except Exception as exc:  # libsumo's own exception does not pickle to a parent process
        raise RuntimeError(f"SUMO could not load the warm-up state {path}: {exc}") from None


def write_warm_state(
    scenario: ScenarioFiles, level: float, seed: int, warmup_s: int, path: Path
) -> None:
    """Simulate the warm-up in a fresh ``sumo`` process and save its state.

    A separate process keeps the result independent of whatever this process
    simulated before (libsumo keeps some random state across restarts).

    Raises:
        RuntimeError: if SUMO fails (its message in one line).
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".xml")
    os.close(fd)
    begin = scenario.begin_s
    args = [
        sumo_binary("sumo"),
        *sumo_args(scenario, level, seed),
        "--end",
        f"{begin + warmup_s + 1:g}",
        "--save-state.times",
        f"{begin + warmup_s:g}",
        "--save-state.files",
        tmp,
    ]
    proc = subprocess.run(args, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        Path(tmp).unlink(missing_ok=True)
        detail = " ".join(proc.stderr.split())[-2000:]  # one line: SUMO's own span several
        raise RuntimeError(f"SUMO warm-up failed ({proc.returncode}): {detail}")
    os.replace(tmp, path)
