"""Training throughput against the serial bound, measured in one run.

Three measurements, in this order:

1. ``t_env``: one bare ``UrbanDriveEnv.step`` of the episodes the run will play (a random
   safe driver, resets not timed), in this process;
2. ``t_update``: one learner update of the preset (batch, masks and n-step targets
   included), on one torch thread;
3. the trainer itself on ``--envs`` SUMO worker processes with the preset's update ratio
   (one update per ``train_frequency`` transitions), from the first update on: env steps
   per second between the first ``episodes.csv`` row written after ``learning_starts``
   and the last one.

The serial bound is what a loop that neither overlaps nor wastes anything would reach:
1 / (t_env + t_update / train_frequency). Target: trainer / bound >= 0.5. The seeds of the
run's pool are warmed up before anything is timed, so that the figure is the steady state
of a run whose warm-up states are cached (the first run on a machine also builds them).

With ``--ray`` the same run is repeated with the workers as actors on a local Ray and the
ratio of its throughput to the local process workers' is printed (target >= 0.8).

    python benchmarks/bench_train.py [--episodes 40] [--envs 2] [--seed-pool 8] [--ray]
"""

from __future__ import annotations

import argparse
import csv
import tempfile
import time
from pathlib import Path

import numpy as np
import torch

from explaindrive.agent.buffer import ReplayBuffer
from explaindrive.agent.config import TrainConfig, preset
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.schedule import plan_episode
from explaindrive.agent.shield import runtime_mask, training_mask
from explaindrive.agent.trainer import train
from explaindrive.env.urban_drive import UrbanDriveEnv


def env_step_time(config: TrainConfig, episodes: int, rng: np.random.Generator) -> float:
    """Mean seconds of one env step over the run's first ``episodes`` plans (warms them)."""
    env = UrbanDriveEnv()
    elapsed, steps = 0.0, 0
    try:
        for index in range(episodes):
            plan = plan_episode(config, index)
            obs, _ = env.reset(seed=plan.seed, options=plan.reset_options())
            while True:
                action = int(rng.choice(np.flatnonzero(runtime_mask(obs))))
                t0 = time.perf_counter()
                obs, _, terminated, truncated, _ = env.step(action)
                elapsed += time.perf_counter() - t0
                steps += 1
                if terminated or truncated:
                    break
    finally:
        env.close()
    return elapsed / steps


def update_time(config: TrainConfig, rng: np.random.Generator, updates: int = 1000) -> float:
    """Mean seconds of one learner update of ``config`` on one thread."""
    torch.set_num_threads(1)
    buffer = ReplayBuffer(20_000)
    low = np.array([0, 0, 8.33, 0, -5, 0, 0, 0], np.float32)
    high = np.array([2, 14, 13.89, 200, 10, 200, 2, 200], np.float32)
    obs = rng.uniform(low, high, (20_000, 8)).astype(np.float32)
    mask = training_mask(obs)
    buffer.add(obs, rng.integers(0, 7, len(obs)), rng.normal(size=len(obs)), obs,
               np.zeros(len(obs), bool), config.gamma**config.n_step, mask, mask)  # fmt: skip
    learner = D3QNLearner(config)
    for _ in range(50):
        learner.update(buffer.sample(config.batch_size, rng), 0)
    t0 = time.perf_counter()
    for _ in range(updates):
        learner.update(buffer.sample(config.batch_size, rng), 0)
    return (time.perf_counter() - t0) / updates


def trainer_rate(config: TrainConfig, out: Path, use_ray: bool = False) -> tuple[float, int]:
    """Env steps/s of the trainer once updates run, and the steps that rate spans."""
    train(config, out, use_ray=use_ray)
    with (out / "episodes.csv").open(newline="") as f:
        rows = [r for r in csv.DictReader(f) if int(r["env_steps"]) > config.learning_starts]
    if len(rows) < 2:
        raise SystemExit(
            f"fewer than 2 episodes ended after the first {config.learning_starts} env steps "
            "(no updates before them): raise --episodes"
        )
    first, last = rows[0], rows[-1]
    steps = int(last["env_steps"]) - int(first["env_steps"])
    return steps / (float(last["wall_time_s"]) - float(first["wall_time_s"])), steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="safe", choices=["safe", "paper"])
    parser.add_argument("--episodes", type=int, default=40, help="episodes the trainer plays")
    parser.add_argument("--envs", type=int, default=2, help="SUMO worker processes")
    parser.add_argument("--seed-pool", type=int, default=8, help="seeds the episodes use")
    parser.add_argument("--ray", action="store_true", help="also train with Ray workers")
    args = parser.parse_args()

    config = preset(args.preset).replace(
        episodes=args.episodes, num_envs=args.envs, seed_pool=args.seed_pool,
        learning_starts=2_000, stop_when_safe=None, checkpoint_every_episodes=10**6,
    )  # fmt: skip
    rng = np.random.default_rng(0)
    t_env = env_step_time(config, args.episodes, rng)
    t_update = update_time(config, rng)
    bound = 1.0 / (t_env + t_update / config.train_frequency)
    with tempfile.TemporaryDirectory() as tmp:
        rate, steps = trainer_rate(config, Path(tmp) / "run")
        if args.ray:
            ray_rate, ray_steps = trainer_rate(config, Path(tmp) / "ray", use_ray=True)

    print(f"preset, envs, episodes       {args.preset}, {args.envs}, {args.episodes}")
    print(f"bare env step                {t_env * 1e3:8.3f} ms")
    print(f"learner update (batch {config.batch_size})   {t_update * 1e3:8.3f} ms")
    print(f"updates per env step         {1 / config.train_frequency:8.2f}")
    print(f"serial bound                 {bound:8.0f} env steps/s")
    print(f"trainer, {steps:,} steps       {rate:8.0f} env steps/s")
    print(f"ratio trainer / bound        {rate / bound:8.2f}   (target >= 0.5)")
    if args.ray:
        print(f"trainer on Ray, {ray_steps:,} steps {ray_rate:8.0f} env steps/s")
        print(f"ratio Ray / local processes  {ray_rate / rate:8.2f}   (target >= 0.8)")


if __name__ == "__main__":
    main()
