"""Choose the fast and comfort networks to ship, by the rule of explaindrive.evaluation.selection.

    python scripts/choose_policies.py --fast runs/r5-fast/seed-0 runs/r5-fast/seed-1 \
        --comfort runs/r6-comfort/seed-0 runs/r6-comfort/seed-1 --out out/validation

Every candidate (and the networks shipped today, unless ``--no-shipped``) is evaluated bare
on the four validation grids: seeds 1000-1009 x the five traffic levels with the stops at
60-75 and 150-165 s, without them, and without them under observation noise of 2 m / 0.6
m/s and of 3 m / 0.9 m/s; Krauss and IDM on the noise-free grid. Each evaluation is stored
under ``--out`` (in a folder named after the policy file and its content's hash) in the
format of ``explaindrive evaluate --json`` and reused when the script runs again. The stops
grid of a run that ``train --seeds`` trained is read from its ``seeds.json``, which holds
exactly that grid. Prints one table per policy, best first, and the pair to ship.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import re
import sys
from dataclasses import fields
from pathlib import Path
from typing import Any

from explaindrive.agent.checkpoint import CheckpointError
from explaindrive.agent.controller import QPolicy
from explaindrive.evaluation.aggregate import Aggregate, aggregate
from explaindrive.evaluation.parsing import parse_seeds
from explaindrive.evaluation.runner import run_grid
from explaindrive.evaluation.schema import read_runs, run_document, write_json
from explaindrive.evaluation.selection import GRIDS, Candidate, Judgement, choose_pair, rank
from explaindrive.evaluation.spec import parse_policy, plan_run
from explaindrive.evaluation.sweep import DEFAULT_EVAL_SEEDS, DEFAULT_EVAL_STOPS
from explaindrive.evaluation.tables import fmt, markdown_table
from explaindrive.sim.scenario.layout import TRAFFIC_LEVELS

NOISE = (2.0, 0.6)  # [m, m/s] the noise grid's observation noise
HEAVY_NOISE = (3.0, 0.9)  # [m, m/s] the heavy-noise grid's


GRID_OPTIONS: dict[str, dict[str, Any]] = {
    "stops": {"stop_schedule": DEFAULT_EVAL_STOPS},
    "noise_free": {},
    "noise": {"obs_noise": NOISE},
    "heavy_noise": {"obs_noise": HEAVY_NOISE},
}
"""plan_run's options of each validation grid."""


def folder(policy: str) -> str:
    """The folder name of a policy's evaluations: its name or path, and for a network the
    start of its file's SHA-256, so that a shipped network replaced later is not mistaken
    for the one evaluated before."""
    name = re.sub(r"[^A-Za-z0-9.-]+", "_", policy.strip("/")) or "policy"
    paths = parse_policy(policy, shield=False).paths
    if not paths:
        return name
    digest = hashlib.sha256(Path(paths[0]).read_bytes()).hexdigest()[:12]
    return f"{name}-{digest}"


def evaluated(policy: str, grid: str, out: Path, workers: int) -> Aggregate:
    """The bare figures of ``policy`` on ``grid``, from ``out`` or evaluated and stored."""
    path = out / folder(policy) / f"{grid}.json"
    if not path.is_file():
        spec = parse_policy(policy, shield=False)
        seeds = parse_seeds(DEFAULT_EVAL_SEEDS)
        plan = plan_run(spec, seeds, TRAFFIC_LEVELS, **GRID_OPTIONS[grid])
        print(f"evaluating {policy} on the {grid} grid ...", file=sys.stderr, flush=True)
        records = run_grid(plan.episodes, workers=workers)
        write_json(path, [run_document(plan.name, records, include_traces=False)])
    (run,) = read_runs(path)
    return aggregate([result for _, _, result in run.episodes])


def trained_stops_grid(run: str) -> Aggregate | None:
    """The stops grid's figures that ``train --seeds`` wrote beside ``run``, if any."""
    table = Path(run).parent / "seeds.json"
    if not table.is_file():
        return None
    for row in json.loads(table.read_text(encoding="utf-8")):
        if Path(row["run"]).resolve() == Path(run).resolve():
            names = {f.name for f in fields(Aggregate)}
            return Aggregate(**{k: v for k, v in row["overall"].items() if k in names})
    return None


def candidate(
    policy: str, mode: str, out: Path, workers: int, name: str | None = None
) -> Candidate:
    """A candidate with its figures on every grid."""
    path = parse_policy(policy, shield=False).paths[0]
    rule = QPolicy.load(path).yellow_leader
    grids = {}
    for grid in GRIDS:
        stored = trained_stops_grid(policy) if grid == "stops" else None
        grids[grid] = stored or evaluated(policy, grid, out, workers)
    return Candidate(name or policy, mode, rule, grids)


def table(judged: list[Judgement]) -> str:
    """One row per candidate, best first."""
    names = [t.name for t in judged[0].targets]
    header = ["candidate", "yellow", "violations", "shortfall", "targets met", *names]
    rows = [
        [
            j.candidate.name, j.candidate.yellow_leader, str(j.violations),
            f"{j.shortfall:.3f}", f"{j.met}/{len(j.targets)}",
            *(f"{fmt(t.value)} ({t.bound})" for t in j.targets),
        ]
        for j in judged
    ]  # fmt: skip
    return markdown_table(header, rows)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fast", nargs="*", default=[], help="fast runs or policy files")
    parser.add_argument("--comfort", nargs="*", default=[], help="comfort runs or policy files")
    parser.add_argument("--no-shipped", action="store_true", help="leave the shipped networks out")
    parser.add_argument("--out", type=Path, default=Path("out/validation"))
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args()
    wanted: list[tuple[str, str, str | None]] = [(p, "fast", None) for p in args.fast]
    wanted += [(p, "comfort", None) for p in args.comfort]
    if not args.no_shipped:
        wanted += [("fast", "fast", "shipped fast"), ("comfort", "comfort", "shipped comfort")]
    try:
        cands = [candidate(p, m, args.out, args.workers, n) for p, m, n in wanted]
        krauss = evaluated("krauss", "noise_free", args.out, args.workers)
        idm = evaluated("idm", "noise_free", args.out, args.workers)
    except (CheckpointError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    levels = ",".join(map(str, TRAFFIC_LEVELS))
    print(f"bare networks, seeds {DEFAULT_EVAL_SEEDS} x traffic {levels};"
          " targets on the noise-free grid against Krauss and IDM\n")  # fmt: skip
    for mode in ("fast", "comfort"):
        judged = rank([c for c in cands if c.mode == mode], krauss, idm)
        if judged:
            print(f"## {mode}\n\n{table(judged)}\n")
    try:
        pair = choose_pair(cands, krauss, idm)
    except ValueError as exc:
        print(f"no pair to ship: {exc}")
        return 1
    print(f"ship: fast {pair.fast.candidate.name}, comfort {pair.comfort.candidate.name}"
          f" (yellow rule {pair.fast.candidate.yellow_leader})")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
