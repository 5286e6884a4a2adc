"""Evaluate several training runs of one policy on the same grid: one row per run, mean, spread.

    python scripts/compare_seeds.py runs/fast-s0 runs/fast-s1 runs/fast-s2 \
        --seeds 1000-1009 [--stop-schedule 60-75,150-165] [--shield] [--out table.md]

The bare networks are evaluated unless ``--shield``. Validation seeds (1000 onwards) are
kept apart from the evaluation seeds the README reports (0-49) and from the training pool
(100000 onwards), so the run chosen to ship is not chosen on the figures it is judged by.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from explaindrive.evaluation.parsing import parse_levels, parse_seeds
from explaindrive.evaluation.seeds import evaluate_runs, seed_table
from explaindrive.evaluation.sweep import DEFAULT_EVAL_SEEDS
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", help="training run directories or policy files")
    parser.add_argument("--seeds", default=DEFAULT_EVAL_SEEDS)
    parser.add_argument("--traffic", default=",".join(f"{x:g}" for x in TRAFFIC_LEVELS))
    parser.add_argument("--stop-schedule", default=None)
    parser.add_argument("--shield", action="store_true", help="evaluate with the shield on")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--out", type=Path, default=None, help="also write the table here")
    args = parser.parse_args()
    results = evaluate_runs(
        args.runs, parse_seeds(args.seeds), parse_levels(args.traffic),
        stop_schedule=args.stop_schedule, shield=args.shield, workers=args.workers,
    )  # fmt: skip
    grid = f"seeds {args.seeds}, traffic {args.traffic}"
    if args.stop_schedule:
        grid += f", stops {args.stop_schedule}"
    text = f"{'shielded' if args.shield else 'bare networks'}, {grid}\n\n{seed_table(results)}\n"
    print(text)
    if args.out is not None:
        args.out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
