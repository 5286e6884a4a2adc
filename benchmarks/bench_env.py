"""Env steps per second next to raw SUMO stepping of the same scenario with the same traffic.

For each seed, two stretches run back to back from the same warmed-up state:

* env: ``UrbanDriveEnv.step`` driven by the cautious rule-based driver; only ``step`` is
  timed (observation, reward, violation checks, metrics, subscriptions);
* raw: the same episode replayed with bare libsumo: no subscriptions, the ego's speed set
  to the value the env episode produced, pedestrians added from the same seeded demand,
  then ``simulationStep``. The traffic is therefore the same vehicle for vehicle, and the
  difference is what the env adds on top of SUMO.

Pairing the stretches seed by seed keeps slow drifts of the machine's load out of the
ratio. Target: env >= 75 % of raw.

    python benchmarks/bench_env.py [--episodes 60] [--traffic 1.0]
"""

from __future__ import annotations

import argparse
import statistics
import time

from explaindrive.env.actions import STEP_LENGTH_S
from explaindrive.env.scripted import CautiousDriver
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.sim.pedestrians import PedestrianSource
from explaindrive.sim.scenario.files import EGO_ID


def env_stretch(env: UrbanDriveEnv, seed: int, traffic: float) -> tuple[float, list[float]]:
    """Seconds spent in ``env.step`` over one episode, and the ego speed after each step."""
    driver = CautiousDriver()
    obs, _ = env.reset(seed=seed, options={"traffic_level": traffic})
    elapsed, speeds = 0.0, []
    while True:
        action = driver(obs)
        t0 = time.perf_counter()
        obs, _, terminated, truncated, info = env.step(action)
        elapsed += time.perf_counter() - t0
        speeds.append(float(info["speed_mps"]))
        if terminated or truncated:
            return elapsed, speeds


def raw_stretch(env: UrbanDriveEnv, seed: int, traffic: float, speeds: list[float]) -> float:
    """Seconds of bare SUMO stepping that replays ``speeds`` from the same start."""
    env.reset(seed=seed, options={"traffic_level": traffic})
    api = env.sumo
    api.vehicle.unsubscribe(EGO_ID)
    api.simulation.unsubscribe("")
    for tls_id in api.trafficlight.getIDList():
        api.trafficlight.unsubscribe(tls_id)
    for edge in api.edge.getIDList():
        api.edge.unsubscribe(edge)
    pedestrians = PedestrianSource(seed, horizon_s=env.config.max_steps + 1.0)
    t0 = time.perf_counter()
    for i, v in enumerate(speeds):
        api.vehicle.setSpeed(EGO_ID, v)
        pedestrians.step(api, i * STEP_LENGTH_S)
        api.simulationStep()
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=60)
    parser.add_argument("--traffic", type=float, default=1.0)
    args = parser.parse_args()
    env = UrbanDriveEnv()
    env_s = raw_s = 0.0
    steps = 0
    ratios = []
    try:
        env_stretch(env, 10_000, args.traffic)  # warm caches and the warm-up state files
        for seed in range(args.episodes):
            e, speeds = env_stretch(env, seed, args.traffic)
            r = raw_stretch(env, seed, args.traffic, speeds)
            env_s, raw_s, steps = env_s + e, raw_s + r, steps + len(speeds)
            ratios.append(r / e)
            print(
                f"seed {seed:3d}: {len(speeds):4d} steps  raw {len(speeds) / r:6.0f}/s  "
                f"env {len(speeds) / e:6.0f}/s  ratio {r / e:.2f}"
            )
    finally:
        env.close()
    print(f"traffic level          {args.traffic:g}")
    print(f"episodes, steps        {args.episodes}, {steps}")
    print(f"raw SUMO steps/s       {steps / raw_s:8.0f}")
    print(f"env steps/s            {steps / env_s:8.0f}")
    print(f"ratio env/raw          {raw_s / env_s:8.2f}   (target >= 0.75)")
    print(
        f"per-episode ratio      median {statistics.median(ratios):.2f}, "
        f"min {min(ratios):.2f}, max {max(ratios):.2f}"
    )


if __name__ == "__main__":
    main()
