"""Recorded episodes that pin the environment's behaviour step by step.

Each case is a seeded episode driven by a seeded driver; :func:`record` plays it and
returns every step's observation, reward, termination flags and info. The recording in
``data/golden_episodes.json.gz`` was made with ``python -m tests.env.golden`` and
``test_golden.py`` replays the cases against it.
"""

from __future__ import annotations

import gzip
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from explaindrive.env.actions import N_ACTIONS
from explaindrive.env.scripted import AlwaysAccelerate, CautiousDriver, ConstantSpeed

GOLDEN_FILE = Path(__file__).parent / "data" / "golden_episodes.json.gz"

CASES: dict[str, dict[str, Any]] = {
    "cautious_with_stops": {
        "config": {"traffic_level": 1.0, "max_steps": 400},
        "seed": 3,
        "options": {"command": "comfort", "command_schedule": [[20, "stop"], [30, "comfort"]]},
        "driver": "cautious",
        "explore": 0.05,
    },
    "constant_speed_violations": {
        "config": {"traffic_level": 1.25, "max_steps": 200},
        "seed": 1,
        "options": None,
        "driver": "constant8",
        "explore": 0.0,
    },
    "reckless_collision": {
        "config": {"traffic_level": 1.0, "max_steps": 200},
        "seed": 0,
        "options": None,
        "driver": "accelerate",
        "explore": 0.0,
    },
    "noisy_normalised": {
        "config": {"traffic_level": 0.5, "max_steps": 60, "normalize_obs": True},
        "seed": 7,
        "options": {"command": "fast", "obs_noise": [1.0, 0.5]},
        "driver": "random",
        "explore": 1.0,
    },
    "krauss_baseline": {
        "config": {"traffic_level": 1.0, "max_steps": 60, "ego_model": "krauss"},
        "seed": 2,
        "options": {"command_schedule": [[15, "stop"]]},
        "driver": "random",
        "explore": 1.0,
    },
    "generated_scenario": {
        "config": {"scenario": "random", "scenario_every": 1, "max_steps": 150, "warmup_s": 60},
        "seed": 11,
        "options": {"command": "comfort"},
        "driver": "cautious",
        "explore": 0.1,
    },
    "two_lane_grid": {
        "config": {"route": ["A0B0", "D3D4"], "max_steps": 150, "warmup_s": 0},
        "netgen": [
            "--grid.number",
            "5",
            "--grid.length",
            "200",
            "--default-junction-type",
            "traffic_light",
            "--default.lanenumber",
            "2",
        ],
        "seed": 0,
        "options": None,
        "driver": "cautious",
        "explore": 0.1,
    },
}


def _plain(value: Any) -> Any:
    """JSON-ready copy (arrays to lists, numpy scalars to Python numbers)."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_plain(v) for v in value]
    if isinstance(value, np.bool_ | bool):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating | float):
        return float(value)
    return value


def grid_net(directory: Path, options: list[str]) -> Path:
    """A network made by SUMO's ``netgenerate --grid`` with ``options``."""
    import subprocess

    from explaindrive.sim.sumo_home import sumo_binary

    out = directory / "grid.net.xml"
    args = [sumo_binary("netgenerate"), "--grid", *options, "-o", str(out),
            "--seed", "7", "--no-turnarounds", "true"]  # fmt: skip
    subprocess.run(args, check=True, capture_output=True)
    return out


def _checked_mask(obs: np.ndarray, info: dict[str, Any]) -> dict[str, Any]:
    """``info`` without its action mask, after checking that the mask is the shield's rule
    on the true state (the recording does not hold the mask)."""
    from explaindrive.env.safety import runtime_mask

    info = dict(info)
    mask = info.pop("action_mask")
    true_obs = info.get("true_obs", obs)
    assert mask.dtype == np.bool_ and np.array_equal(mask, runtime_mask(true_obs)), info["time_s"]
    return info


def record(make_env: Any, case: dict[str, Any], tmp_dir: Path) -> list[dict[str, Any]]:
    """Play one case; the first record is the reset's (obs, info)."""
    from explaindrive.env import state as S

    config = dict(case["config"])
    if "netgen" in case:
        config["net_file"] = grid_net(tmp_dir, case["netgen"])
    env = make_env(**config)
    drivers = {"cautious": CautiousDriver(), "constant8": ConstantSpeed(8),
               "accelerate": AlwaysAccelerate(), "random": None}  # fmt: skip
    driver = drivers[case["driver"]]
    rng = np.random.default_rng(case["seed"])
    obs, info = env.reset(seed=case["seed"], options=case["options"])
    steps = [{"obs": _plain(obs), "info": _plain(_checked_mask(obs, info))}]
    done = False
    while not done:
        raw = S.denormalize(obs) if case["config"].get("normalize_obs") else obs
        explore = rng.random() < case["explore"]
        action = int(rng.integers(N_ACTIONS)) if explore or driver is None else driver(raw)
        obs, reward, terminated, truncated, info = env.step(action)
        done = terminated or truncated
        steps.append({
            "action": action, "obs": _plain(obs), "reward": float(reward),
            "terminated": terminated, "truncated": truncated,
            "info": _plain(_checked_mask(obs, info)),
        })  # fmt: skip
    return steps


def load_golden() -> dict[str, list[dict[str, Any]]]:
    """The recorded episodes, by case name."""
    return json.loads(gzip.decompress(GOLDEN_FILE.read_bytes()))


def assert_same(got: Any, want: Any, where: str = "") -> None:
    """Equal structure, strings and flags; floats within 1e-6 (relative or absolute)."""
    if isinstance(want, dict):
        assert isinstance(got, dict) and sorted(got) == sorted(want), f"{where}: keys differ"
        for key in want:
            assert_same(got[key], want[key], f"{where}.{key}")
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), f"{where}: lengths differ"
        for i, (g, w) in enumerate(zip(got, want, strict=True)):
            assert_same(g, w, f"{where}[{i}]")
    elif isinstance(want, float) and not isinstance(want, bool):
        assert isinstance(got, int | float), f"{where}: {got!r} is not a number"
        if math.isinf(want):
            assert got == want, f"{where}: {got} != {want}"
        else:
            assert math.isclose(got, want, rel_tol=1e-6, abs_tol=1e-6), f"{where}: {got} != {want}"
    else:
        assert got == want, f"{where}: {got!r} != {want!r}"


def _main() -> None:
    from explaindrive.env.urban_drive import UrbanDriveEnv

    made: list[UrbanDriveEnv] = []

    def make_env(**kwargs: Any) -> UrbanDriveEnv:
        for env in made:
            env.close()
        made.append(UrbanDriveEnv(**kwargs))
        return made[-1]

    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        recorded = {name: record(make_env, case, Path(tmp)) for name, case in CASES.items()}
    for env in made:
        env.close()
    text = json.dumps(recorded, separators=(",", ":")) + "\n"
    GOLDEN_FILE.write_bytes(gzip.compress(text.encode(), mtime=0))
    for name, steps in recorded.items():
        print(name, len(steps) - 1, "steps")


if __name__ == "__main__":
    _main()
