"""Several training seeds of one policy side by side, then one evaluation of each.

``explaindrive train --mode fast --seeds 0,1,2 --out runs/fast`` starts one training
process per seed (``runs/fast/seed-<s>``, log in ``runs/fast/seed-<s>.log``), each with the
same options (``--ray`` included: their workers then share the cluster), waits for all, then
evaluates every finished policy on the same grid and writes the combined table
(``seeds.md``, one row per seed with mean and spread; ``seeds.json``) into the run folder.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

from explaindrive.evaluation.paper import PAPER_STOP_SCHEDULE
from explaindrive.evaluation.seeds import SeedResult, evaluate_runs, seed_table

DEFAULT_EVAL_SEEDS = "1000-1009"
"""Validation seeds: apart from the README's evaluation seeds (0-49) and the training pool."""
DEFAULT_EVAL_STOPS = PAPER_STOP_SCHEDULE
"""The stop injections of the seed table: the paper's."""


def seed_run_dir(out: Path, seed: int) -> Path:
    """The run folder of one seed."""
    return out / f"seed-{seed}"


def _seeds_in(out: Path) -> set[int]:
    """The seeds of the ``seed-<s>`` run folders in ``out``."""
    found = set()
    for path in out.glob("seed-*"):
        suffix = path.name.removeprefix("seed-")
        if path.is_dir() and suffix.isdigit():
            found.add(int(suffix))
    return found


def train_seeds(train_args: Sequence[str], seeds: Sequence[int], out: Path) -> dict[int, int]:
    """Run ``explaindrive train <train_args> --seed s --out out/seed-s`` for every seed at
    once; returns each process's exit status."""
    out.mkdir(parents=True, exist_ok=True)
    procs = {}
    for seed in seeds:
        run = ["--seed", str(seed), "--out", str(seed_run_dir(out, seed)), "--no-progress"]
        argv = [sys.executable, "-m", "explaindrive.cli.main", "train", *train_args, *run]
        with (out / f"seed-{seed}.log").open("ab") as log:
            procs[seed] = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT)
    return {seed: proc.wait() for seed, proc in procs.items()}


def evaluate_seeds(
    out: Path,
    seeds: Sequence[int],
    eval_seeds: Sequence[int],
    levels: Sequence[float],
    stop_schedule: str | None,
    workers: int | None = None,
) -> list[SeedResult]:
    """Evaluate the bare network of every seed that finished; write ``seeds.md``/``.json``.

    The table covers the folder: seeds that earlier ``--seeds`` commands trained into ``out``
    are evaluated again beside ``seeds``, so separate commands never overwrite each other's
    rows."""
    runs = [str(seed_run_dir(out, s)) for s in sorted(set(seeds) | _seeds_in(out))
            if (seed_run_dir(out, s) / "policy.pt").is_file()]  # fmt: skip
    results = evaluate_runs(
        runs, eval_seeds, levels, stop_schedule=stop_schedule, shield=False, workers=workers
    )
    grid = f"seeds {min(eval_seeds)}-{max(eval_seeds)} x traffic {','.join(map(str, levels))}"
    if stop_schedule:
        grid += f", stops at {stop_schedule} s"
    text = f"# Training seeds: bare networks, {grid}\n\n{seed_table(results)}\n"
    (out / "seeds.md").write_text(text, encoding="utf-8")
    doc = [{"run": r.run, "steps": r.steps, "shield_overrides": r.shield_overrides,
            "overall": asdict(r.overall)} for r in results]  # fmt: skip
    (out / "seeds.json").write_text(json.dumps(doc, indent=2), encoding="utf-8")
    return results
