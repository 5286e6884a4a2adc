"""Would the reward pay for a faster cruise than the network drives? Each episode twice.

    python scripts/cruise_counterfactual.py runs/comfort/seed-2/policy.pt \
        --seeds 1000-1004 --traffic 0.5,1.0 [--below 1] [--scenarios random:104,105]

Every episode runs once on the bare network's greedy choice and once on the same choice
except on a free road (:func:`~explaindrive.env.ride_quality.free_road`, as the ride figures
define it): where the network would not accelerate and the car is more than ``--below`` m/s
under the highest whole speed within the posted limit, it takes +1 m/s if the safety rule
allows it. Both runs collect the reward of the network's own recipe (its card) under its
own command; the script prints both returns and the terms that differ by more than 0.5.

A higher return for the forced cruise on most episodes says the network's values, not its
reward, keep it slow: its value of the faster speed is too low. ``--scenarios`` drives
generated scenarios held out from training instead of the paper's road.

With ``--approach`` the second run forces a later braking instead: approaching a red or
yellow light that is its leader (no vehicle closer), where the network would slow down, the
car keeps its speed if it could still stand :data:`APPROACH_STANDSTILL_M` before the line
after one more step at that speed, braking at ``--approach`` m/s^2 (the free bound of the
passenger reward's approach term: 1.5), and the safety rule allows keeping it. A higher
return then says the values, not the reward, make it brake early.
"""

from __future__ import annotations

import argparse
import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np

from explaindrive.agent.controller import QPolicy
from explaindrive.cache import cache_dir
from explaindrive.env import state as S
from explaindrive.env.actions import IDLE_ACTION, action_index, speed_change
from explaindrive.env.config import EnvConfig
from explaindrive.env.reward import APPROACH_STANDSTILL_M
from explaindrive.env.ride_quality import is_free_road
from explaindrive.env.safety import TRUE_VIRTUAL_TOL_M, safe_action_mask
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.evaluation.parsing import parse_levels, parse_seeds
from explaindrive.evaluation.scenarios import PAPER_ROAD, ScenarioCase, parse_scenarios

ACCELERATE = action_index(1)


def holds_for_light(obs: np.ndarray, decel_mps2: float) -> bool:
    """Whether, approaching a red or yellow light that is its leader, the car could keep its
    speed one more step and still stand :data:`APPROACH_STANDSTILL_M` before the line braking
    at ``decel_mps2``."""
    v, d_tl = float(obs[S.V_EGO]), float(obs[S.D_TL])
    light_ahead = obs[S.TLS] != 0 and d_tl < S.SENSOR_RANGE_M
    light_leads = abs(float(obs[S.D_LEAD]) - d_tl) < TRUE_VIRTUAL_TOL_M
    return bool(
        light_ahead and light_leads and v > 0
        and v * v / (2.0 * decel_mps2) <= d_tl - v - APPROACH_STANDSTILL_M
    )  # fmt: skip


def episode(
    policy: QPolicy,
    seed: int,
    traffic: float,
    below: float | None,
    approach: float | None = None,
    where: ScenarioCase = PAPER_ROAD,
) -> tuple[float, int, int, dict[str, float]]:
    """One episode on ``where``: its return, steps, forced steps and the sum of each reward
    term."""
    mode = str(policy.card["mode"])
    config = policy.card.get("config", {})
    env = UrbanDriveEnv(
        config=EnvConfig(
            **dict(where.fields),
            traffic_level=traffic,
            yellow_leader=policy.yellow_leader,
            reward=config.get("reward", "paper"),
            stop_window_m=config.get("stop_window_m"),
        )
    )
    try:
        obs, info = env.reset(seed=seed, options={"command": mode, "traffic_level": traffic})
        total, steps, forced, terms = 0.0, 0, 0, dict[str, float]()
        free, done = False, False
        while not done:
            action = int(np.argmax(policy.q_values(obs)))
            if below is not None and free and speed_change(action) <= 0:
                highest = math.floor(float(obs[S.V_LIM]) + 1e-9)
                if obs[S.V_EGO] < highest - below - 1e-6 and safe_action_mask(obs)[ACCELERATE]:
                    action, forced = ACCELERATE, forced + 1
            if (
                approach is not None
                and speed_change(action) < 0
                and holds_for_light(obs, approach)
                and safe_action_mask(obs)[IDLE_ACTION]
            ):
                action, forced = IDLE_ACTION, forced + 1
            obs, reward, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            free = is_free_road(info)
            total, steps = total + float(reward), steps + 1
            for name, value in info["reward_terms"].items():
                terms[name] = terms.get(name, 0.0) + float(value)
        return total, steps, forced, terms
    finally:
        env.close()


def _differences(forced: dict[str, Any], as_is: dict[str, Any]) -> str:
    diff = {k: forced.get(k, 0.0) - as_is.get(k, 0.0) for k in sorted({*forced, *as_is})}
    return ", ".join(f"{k} {v:+.1f}" for k, v in diff.items() if abs(v) > 0.5 and k != "total")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("policy", type=Path, help="a policy .pt file")
    parser.add_argument("--seeds", default="1000-1004", help="e.g. 1000-1004 (validation seeds)")
    parser.add_argument("--traffic", default="0.5,1.0", help="comma-separated traffic levels")
    parser.add_argument(
        "--below", type=float, default=1.0, help="force +1 while this far under the top speed"
    )
    parser.add_argument(
        "--approach",
        type=float,
        default=None,
        help="[m/s^2] force a later braking for lights at this deceleration instead",
    )
    parser.add_argument("--scenarios", help="generated scenarios, e.g. random:104,105")
    args = parser.parse_args()
    wheres = parse_scenarios(args.scenarios, cache_dir()) if args.scenarios else (PAPER_ROAD,)
    policy = QPolicy.load(args.policy)
    below, approach = (None, args.approach) if args.approach is not None else (args.below, None)
    levels = parse_levels(args.traffic)
    print("| road | seed | traffic | return as is | return forced | forced steps "
          "| terms forced - as is |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    better = runs = 0
    for where, seed, traffic in itertools.product(wheres, parse_seeds(args.seeds), levels):
        as_is = episode(policy, seed, traffic, None, where=where)
        forced = episode(policy, seed, traffic, below, approach, where)
        better, runs = better + int(forced[0] > as_is[0]), runs + 1
        print(f"| {where.name} | {seed} | {traffic} | {as_is[0]:.1f} ({as_is[1]} steps) | "
              f"{forced[0]:.1f} ({forced[1]} steps) | {forced[2]} | "
              f"{_differences(forced[3], as_is[3])} |")  # fmt: skip
    what = "later braking" if approach is not None else "cruise"
    print(f"\nthe forced {what} returns more in {better} of {runs} episodes")


if __name__ == "__main__":
    main()
