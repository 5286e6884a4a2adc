"""Copy a trained policy into the package and complete its card with evaluation figures.

    python scripts/ship_policy.py --run runs/fast --name fast --evaluation out/eval/fast.json

The run's training log (``episodes.csv``) ships next to it as ``<name>_episodes.csv``.
The evaluation file is the ``--json`` output of ``explaindrive evaluate`` on the
paper's grid (5 seeds x 5 traffic levels); its overall aggregate and the command
that produced it go into the card's ``evaluation`` field.
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

POLICY_DIR = Path(__file__).resolve().parents[1] / "src" / "explaindrive" / "agent" / "policies"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", type=Path, required=True, help="training run directory")
    parser.add_argument("--name", choices=("fast", "comfort"), required=True)
    parser.add_argument(
        "--evaluation",
        type=Path,
        action="append",
        default=[],
        help="evaluate --json output (repeatable)",
    )
    parser.add_argument(
        "--command",
        action="append",
        default=[],
        help="the command that produced each evaluation file",
    )
    args = parser.parse_args()
    policy, card_file = args.run / "policy.pt", args.run / "policy.json"
    for path in (policy, card_file, args.run / "episodes.csv"):
        if not path.is_file():
            raise SystemExit(f"missing {path}: finish the training run first")
    card = json.loads(card_file.read_text())
    card["name"] = args.name
    evaluations = []
    for i, path in enumerate(args.evaluation):
        doc = json.loads(path.read_text())
        for run in doc["runs"]:
            evaluations.append(
                {
                    "command": args.command[i] if i < len(args.command) else None,
                    "run": run["name"],
                    "policy": run["policy"],
                    "schedule": run["schedule"],
                    "seeds": run["seeds"],
                    "traffic_levels": run["traffic_levels"],
                    "overall": run["aggregates"]["overall"],
                }
            )
    card["evaluation"] = evaluations or None
    POLICY_DIR.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(policy, POLICY_DIR / f"{args.name}.pt")
    shutil.copyfile(args.run / "episodes.csv", POLICY_DIR / f"{args.name}_episodes.csv")
    (POLICY_DIR / f"{args.name}.json").write_text(json.dumps(card, indent=2, sort_keys=True) + "\n")
    print(f"shipped {args.name}: {POLICY_DIR / (args.name + '.pt')}")


if __name__ == "__main__":
    main()
