"""Env steps per second next to raw SUMO stepping of the same scenario and traffic.

Raw: libsumo ``simulationStep`` of the same network, vehicle and pedestrian demand,
with the ego driven by SUMO's own Krauss model (no observation, reward or control).
Env: ``UrbanDriveEnv.step`` driven by the cautious rule-based driver (only ``step`` is timed).
Both run from the same warmed-up state for the same number of steps.
Target: env >= 75 % of raw.

    python benchmarks/bench_env.py [--steps 3000] [--traffic 1.0]
"""

from __future__ import annotations

import argparse
import time

from explaindrive.env.scripted import CautiousDriver
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.sim.pedestrians import PedestrianSource
from explaindrive.sim.scenario.files import EGO_ID


def env_rate(env: UrbanDriveEnv, steps: int, traffic: float) -> tuple[float, int]:
    driver = CautiousDriver()
    done_steps, seed = 0, 0
    elapsed = 0.0
    while done_steps < steps:
        obs, _ = env.reset(seed=seed, options={"traffic_level": traffic})
        while done_steps < steps:
            action = driver(obs)
            t0 = time.perf_counter()
            obs, _, terminated, truncated, _ = env.step(action)
            elapsed += time.perf_counter() - t0
            done_steps += 1
            if terminated or truncated:
                break
        seed += 1
    return done_steps / elapsed, seed


def raw_rate(env: UrbanDriveEnv, steps: int, traffic: float, episodes: int) -> float:
    api = env.sumo
    done_steps, elapsed = 0, 0.0
    seed = 0
    while done_steps < steps:
        env.reset(seed=seed % max(episodes, 1), options={"traffic_level": traffic})
        api.vehicle.unsubscribe(EGO_ID)
        api.vehicle.setSpeedMode(EGO_ID, 31)  # hand the ego back to Krauss
        api.vehicle.setSpeed(EGO_ID, -1)
        pedestrians = PedestrianSource(seed, horizon_s=1000.0)
        t0 = time.perf_counter()
        for i in range(min(400, steps - done_steps)):
            pedestrians.step(api, float(i))
            api.simulationStep()
            done_steps += 1
            if EGO_ID in api.simulation.getArrivedIDList():
                break
        elapsed += time.perf_counter() - t0
        seed += 1
    return done_steps / elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--traffic", type=float, default=1.0)
    args = parser.parse_args()
    env = UrbanDriveEnv()
    try:
        env_sps, episodes = env_rate(env, args.steps, args.traffic)
        raw_sps = raw_rate(env, args.steps, args.traffic, episodes)
    finally:
        env.close()
    print(f"traffic level          {args.traffic:g}")
    print(f"raw SUMO steps/s       {raw_sps:8.0f}")
    print(f"env steps/s            {env_sps:8.0f}")
    print(f"ratio env/raw          {env_sps / raw_sps:8.2f}   (target >= 0.75)")


if __name__ == "__main__":
    main()
