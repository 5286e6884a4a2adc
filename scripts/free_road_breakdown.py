"""Where a network's free-road time goes, against SUMO's Krauss on the same episodes.

    python scripts/free_road_breakdown.py src/explaindrive/agent/policies/fast.pt \
        --seeds 1000-1009 --traffic 0.5,1.0 [--scenarios random:100-119]

The free road is the ride figures' (:func:`~explaindrive.env.ride_quality.is_free_road`: no
vehicle within 50 m, no red or yellow light or busy crossing within 60 m). Each free-road
step of the bare network and of Krauss falls in one class: cruising at 90 % of the posted
limit or more, accelerating, slowing down (by more than 0.5 m/s), or steady below 90 %.
The free-road steps below 60 % of the limit (the ride figures' slow free road) are split
the same way, and by posted limit. For the network's steady steps below 90 % it then prints
the most common contexts: its speed and limit, the light within the 200 m sensor range and
whether a vehicle is in range. ``--scenarios`` drives generated scenarios held out from
training instead of the paper's road.
"""

from __future__ import annotations

import argparse
import collections
from pathlib import Path

from explaindrive.agent.controller import MergedController, QPolicy
from explaindrive.cache import cache_dir
from explaindrive.env.actions import IDLE_ACTION
from explaindrive.env.config import EnvConfig
from explaindrive.env.reward import CRUISE_SHARE
from explaindrive.env.ride_quality import SLOW_SHARE, is_free_road
from explaindrive.env.state import SENSOR_RANGE_M
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.evaluation.parsing import parse_levels, parse_seeds
from explaindrive.evaluation.scenarios import PAPER_ROAD, ScenarioCase, parse_scenarios

CHANGE_MPS = 0.5  # a speed change beyond this is accelerating or slowing down


def free_road_steps(
    policy: QPolicy, driver: str, seed: int, traffic: float, where: ScenarioCase = PAPER_ROAD
) -> list[dict]:
    """The free-road steps of one episode driven by the bare network or by SUMO's ``krauss``
    on ``where``: speed, previous speed, posted limit, light in range and leader in range."""
    mode = str(policy.card["mode"])
    config = EnvConfig(
        **dict(where.fields),
        traffic_level=traffic,
        ego_model="agent" if driver == "network" else driver,
        yellow_leader=policy.yellow_leader,
    )
    env = UrbanDriveEnv(config=config)
    controller = MergedController(policy, policy, mode, use_shield=False)
    steps, previous = [], 0.0
    try:
        obs, _ = env.reset(seed=seed, options={"command": mode, "traffic_level": traffic})
        controller.begin()
        done = False
        while not done:
            controller.follow(env)
            action = controller.act(obs) if driver == "network" else IDLE_ACTION
            obs, _, terminated, truncated, info = env.step(action)
            done = terminated or truncated
            if is_free_road(info):
                light = (
                    f"{info['light_state']} light in range"
                    if info["light_gap_m"] < SENSOR_RANGE_M
                    else "no light in range"
                )
                leader = "vehicle in range" if info["real_gap_m"] < SENSOR_RANGE_M else "no vehicle"
                steps.append({"v": info["speed_mps"], "before": previous,
                              "limit": info["posted_limit_mps"], "light": light,
                              "leader": leader})  # fmt: skip
            previous = info["speed_mps"]
    finally:
        env.close()
    return steps


def kind(step: dict) -> str:
    """The class of one free-road step."""
    if step["v"] >= CRUISE_SHARE * step["limit"]:
        return "cruise"
    if step["v"] > step["before"] + CHANGE_MPS:
        return "accelerating"
    if step["v"] < step["before"] - CHANGE_MPS:
        return "slowing"
    return "steady below 90 %"


def slow(step: dict) -> bool:
    """The step is below 60 % of the limit (the ride figures' slow free road)."""
    return step["v"] < SLOW_SHARE * step["limit"]


def by_limit(steps: list[dict]) -> dict[int, tuple[int, int]]:
    """Posted limit (km/h, to the nearest 10) -> (steps below 60 % of it, free-road steps)."""
    out: dict[int, tuple[int, int]] = {}
    for s in steps:
        kmh = 10 * round(s["limit"] * 3.6 / 10)
        below, total = out.get(kmh, (0, 0))
        out[kmh] = (below + slow(s), total + 1)
    return dict(sorted(out.items()))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("policy", type=Path, help="a policy .pt file")
    parser.add_argument("--seeds", default="1000-1009", help="e.g. 1000-1009 (validation seeds)")
    parser.add_argument("--traffic", default="0.5,1.0", help="comma-separated traffic levels")
    parser.add_argument("--scenarios", help="generated scenarios, e.g. random:100-119")
    args = parser.parse_args()
    policy = QPolicy.load(args.policy)
    wheres = parse_scenarios(args.scenarios, cache_dir()) if args.scenarios else (PAPER_ROAD,)
    steps = {
        driver: [
            s
            for where in wheres
            for seed in parse_seeds(args.seeds)
            for traffic in parse_levels(args.traffic)
            for s in free_road_steps(policy, driver, seed, traffic, where)
        ]
        for driver in ("network", "krauss")
    }
    kinds = ("cruise", "accelerating", "slowing", "steady below 90 %")
    slow_kinds = kinds[1:]
    print("| driver | free-road steps | mean share of the limit | " + " | ".join(kinds)
          + " | below 60 %: " + " | ".join(slow_kinds) + " |")  # fmt: skip
    print("|---|---|---|" + "---|" * (len(kinds) + len(slow_kinds)))
    for driver, driven in steps.items():
        n = max(len(driven), 1)
        counts = collections.Counter(kind(s) for s in driven)
        slow_counts = collections.Counter(kind(s) for s in driven if slow(s))
        share = sum(s["v"] / s["limit"] for s in driven) / n
        cells = " | ".join(f"{100 * counts[k] / n:.1f} %" for k in kinds)
        slow_cells = " | ".join(f"{100 * slow_counts[k] / n:.1f} %" for k in slow_kinds)
        print(f"| {driver} | {len(driven)} | {share:.3f} | {cells} | {slow_cells} |")

    print("\nFree road below 60 % of the limit, by posted limit (share of that limit's steps):\n")
    limits = sorted({kmh for driven in steps.values() for kmh in by_limit(driven)})
    print("| driver | " + " | ".join(f"{kmh} km/h" for kmh in limits) + " |")
    print("|---|" + "---|" * len(limits))
    for driver, driven in steps.items():
        split = by_limit(driven)
        cells = [
            f"{100 * split[kmh][0] / split[kmh][1]:.1f} % of {split[kmh][1]}"
            if kmh in split
            else "–"
            for kmh in limits
        ]
        print(f"| {driver} | " + " | ".join(cells) + " |")

    network = steps["network"]
    steady_slow = [s for s in network if slow(s) and kind(s) == "steady below 90 %"]
    near = sum(s["leader"] == "vehicle in range" for s in steady_slow)
    n = max(len(network), 1)
    alone = len(steady_slow) - near
    print(
        f"\nThe network's steady free-road steps below 60 %: {100 * near / n:.1f} % of its "
        f"free-road steps with a vehicle in sensor range, {100 * alone / n:.1f} % without."
    )
    steady = collections.Counter(
        (round(s["v"]), round(s["limit"], 1), s["light"], s["leader"])
        for s in network
        if kind(s) == "steady below 90 %"
    )
    print("\nThe network's steady free-road steps below 90 % of the limit, by context:\n")
    print("| speed m/s | limit m/s | light | vehicle | steps |")
    print("|---|---|---|---|---|")
    for (v, limit, light, leader), count in steady.most_common(8):
        print(f"| {v} | {limit} | {light} | {leader} | {count} |")


if __name__ == "__main__":
    main()
