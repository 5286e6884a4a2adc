"""Env steps per second next to raw SUMO stepping of the same scenario with the same traffic,
on the paper's road and on generated scenarios.

For each seed, two stretches run back to back from the same warmed-up state:

* env: ``UrbanDriveEnv.step`` driven by the cautious rule-based driver; only ``step`` is
  timed (observation, reward, violation checks, metrics, subscriptions);
* raw: the same episode replayed with bare libsumo: no subscriptions, the ego's speed set
  to the value the env episode produced, pedestrians added from the same seeded demand,
  then ``simulationStep``. The traffic is therefore the same vehicle for vehicle, and the
  difference is what the env adds on top of SUMO.

Pairing the stretches seed by seed keeps slow drifts of the machine's load out of the
ratio. Target: env >= 67 % of raw.

The same is measured on ``--generated`` scenarios of the generator (seeds 100, 101, ...;
``--episodes`` spread over them), each episode right after the paper's road's of the same
seed, so that drifts of the machine reach both alike; their env steps/s should be within
10 % of the paper's road, and their env/raw ratio at least the paper's.

    python benchmarks/bench_env.py [--episodes 60] [--traffic 1.0] [--generated 10]
"""

from __future__ import annotations

import argparse
import statistics
import time

from explaindrive.cache import cache_dir
from explaindrive.env.actions import STEP_LENGTH_S
from explaindrive.env.scripted import CautiousDriver
from explaindrive.env.urban_drive import UrbanDriveEnv
from explaindrive.sim.pedestrians import PedestrianSource
from explaindrive.sim.scenario.directory import cached_scenario_dir
from explaindrive.sim.scenario.files import EGO_ID
from explaindrive.sim.scenario.generator import random_params

GENERATED_FIRST_SEED = 100


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
    pedestrians = PedestrianSource(seed, env.scenario.pedestrian_flows)
    t0 = time.perf_counter()
    for i, v in enumerate(speeds):
        api.vehicle.setSpeed(EGO_ID, v)
        pedestrians.step(api, i * STEP_LENGTH_S)
        api.simulationStep()
    return time.perf_counter() - t0


class Tally:
    """Seconds and steps of paired env and raw stretches."""

    def __init__(self, name: str) -> None:
        self.name, self.env_s, self.raw_s, self.steps = name, 0.0, 0.0, 0
        self.ratios: list[float] = []

    def pair(self, env: UrbanDriveEnv, seed: int, traffic: float) -> None:
        e, speeds = env_stretch(env, seed, traffic)
        r = raw_stretch(env, seed, traffic, speeds)
        self.env_s, self.raw_s, self.steps = (
            self.env_s + e,
            self.raw_s + r,
            self.steps + len(speeds),
        )
        self.ratios.append(r / e)
        print(
            f"{self.name} seed {seed:3d}: {len(speeds):4d} steps  raw {len(speeds) / r:6.0f}/s  "
            f"env {len(speeds) / e:6.0f}/s  ratio {r / e:.2f}"
        )

    @property
    def env_rate(self) -> float:
        return self.steps / self.env_s

    def report(self) -> None:
        print(f"{self.name}: steps {self.steps}")
        print(f"  raw SUMO steps/s     {self.steps / self.raw_s:8.0f}")
        print(f"  env steps/s          {self.env_rate:8.0f}")
        print(f"  ratio env/raw        {self.raw_s / self.env_s:8.2f}   (target >= 0.67)")
        print(
            f"  per-episode ratio    median {statistics.median(self.ratios):.2f}, "
            f"min {min(self.ratios):.2f}, max {max(self.ratios):.2f}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=60)
    parser.add_argument("--traffic", type=float, default=1.0)
    parser.add_argument("--generated", type=int, default=10, help="generated scenarios (0: none)")
    args = parser.parse_args()
    paper, generated = Tally("paper"), Tally("generated")
    envs = [UrbanDriveEnv()]
    for i in range(args.generated):
        scenario_seed = GENERATED_FIRST_SEED + i
        directory = cached_scenario_dir(random_params(scenario_seed), f"random-{scenario_seed}",
                                        cache_dir(), scenario_seed)  # fmt: skip
        envs.append(UrbanDriveEnv(scenario=str(directory)))
    try:
        env_stretch(envs[0], 10_000, args.traffic)  # warm caches and the warm-up state files
        envs[0].close()
        for seed in range(args.episodes):
            # one SUMO per process: each env's simulation ends before the next one's starts
            paper.pair(envs[0], seed, args.traffic)
            envs[0].close()
            if args.generated:
                env = envs[1 + seed % args.generated]
                generated.pair(env, seed, args.traffic)
                env.close()
    finally:
        for env in envs:
            env.close()
    print(f"traffic level          {args.traffic:g}")
    paper.report()
    if generated.steps:
        generated.report()
        print(f"generated/paper env steps/s  {generated.env_rate / paper.env_rate:.2f}  "
              "(target >= 0.90)")  # fmt: skip
        ratio_of_ratios = (generated.raw_s / generated.env_s) / (paper.raw_s / paper.env_s)
        print(f"generated/paper env/raw ratio {ratio_of_ratios:.2f}  (target >= 1.0)")


if __name__ == "__main__":
    main()
