"""Agent benchmark: learner updates/s, batched action selection, replay memory.

Usage: ``python benchmarks/bench_agent.py [--preset safe|paper] [--updates 2000]``
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np
import torch
from rich.console import Console
from rich.table import Table

from explaindrive.agent.buffer import ReplayBuffer, replay_nbytes
from explaindrive.agent.config import preset
from explaindrive.agent.learner import D3QNLearner
from explaindrive.agent.shield import training_mask
from explaindrive.env.state import STATE_HIGH, STATE_LOW


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--preset", default="safe", choices=["safe", "paper"])
    parser.add_argument("--updates", type=int, default=2000)
    parser.add_argument("--fill", type=int, default=200_000, help="transitions to store")
    args = parser.parse_args()

    torch.set_num_threads(1)
    config = preset(args.preset)
    rng = np.random.default_rng(0)
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    buffer = ReplayBuffer(config.buffer_size)
    obs = rng.uniform(STATE_LOW, STATE_HIGH, (args.fill, 8)).astype(np.float32)
    t0 = time.perf_counter()
    for start in range(0, args.fill, 2):  # two envs per vector step
        sl = slice(start, start + 2)
        mask = training_mask(obs[sl])
        buffer.add(obs[sl], rng.integers(0, 7, 2), rng.normal(size=2), obs[sl], np.zeros(2, bool),
                   config.gamma**config.n_step, mask, mask)  # fmt: skip
    add_rate = args.fill / (time.perf_counter() - t0)
    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss

    learner = D3QNLearner(config)
    for _ in range(50):
        learner.update(buffer.sample(config.batch_size, rng), 0)
    t0 = time.perf_counter()
    for _ in range(args.updates):
        learner.update(buffer.sample(config.batch_size, rng), 0)
    update_rate = args.updates / (time.perf_counter() - t0)

    batch = obs[:2]
    t0 = time.perf_counter()
    for _ in range(5000):
        learner.act(batch, 0.1, rng)
    act_rate = 5000 / (time.perf_counter() - t0)

    table = Table(title=f"agent benchmark ({args.preset} preset, 1 torch thread)")
    table.add_column("metric")
    table.add_column("value", justify="right")
    table.add_row(f"learner updates/s (batch {config.batch_size})", f"{update_rate:,.0f}")
    table.add_row("act calls/s (2 envs, one forward)", f"{act_rate:,.0f}")
    table.add_row("replay adds/s (2 per call)", f"{add_rate:,.0f}")
    table.add_row(
        f"replay arrays, capacity {config.buffer_size:,}", f"{buffer.nbytes / 1e6:,.0f} MB"
    )
    table.add_row("replay arrays, paper 5M", f"{replay_nbytes(5_000_000) / 1e6:,.0f} MB")
    table.add_row(f"RSS growth for {args.fill:,} stored", f"{(rss1 - rss0) / 1024:,.0f} MB")
    Console().print(table)


if __name__ == "__main__":
    main()
