"""What STOP's explicit path earns: LLM-1 on the calibration pool with and without it.

Usage::

    python scripts/stop_path_ablation.py [--model FILE.npz]

The calibration pool (:func:`explaindrive.language.intent.corpus.calibration_pool`) is
never trained on. For the shipped model (or ``--model``) with its thresholds, with the path
and without, prints the STOP recall, the STOP precision, the lines without a command read
as STOP, the negated stops (kind ``negated_stop``) read as STOP, the accuracy over the
command requests, and the STOP requests read as STOP or asked about (the ask band below
STOP's threshold).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from explaindrive.commands import COMMAND_LABELS
from explaindrive.language.intent.corpus import calibration_pool
from explaindrive.language.intent.reader import LineReader


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", type=Path, default=None, help="an intent model file")
    args = ap.parse_args()
    pool = calibration_pool()
    texts = [e.text for e in pool]
    truth = [e.label if e.label in COMMAND_LABELS else "none" for e in pool]
    print(f"calibration pool: {len(pool)} lines, {truth.count('stop')} STOP requests")
    print(
        "stop path  STOP recall  STOP precision  none read as STOP  negated stops  accuracy"
        "  read or asked"
    )
    for on in (True, False):
        readings = LineReader(args.model, stop_path=on).read(texts)
        got = [r.command or "none" for r in readings]
        heard = sum(
            (g == "stop" or r.ask_stop) and t == "stop"
            for g, r, t in zip(got, readings, truth, strict=True)
        )
        said = [g == "stop" for g in got]
        hits = sum(s and t == "stop" for s, t in zip(said, truth, strict=True))
        negated = sum(
            g == "stop" for g, e in zip(got, pool, strict=True) if e.source.endswith("negated_stop")
        )
        commands = [(g, t) for g, t in zip(got, truth, strict=True) if t != "none"]
        print(
            f"{'on' if on else 'off':9s}  {hits / truth.count('stop'):11.3f}  "
            f"{hits / max(1, sum(said)):14.3f}  "
            f"{sum(s and t == 'none' for s, t in zip(said, truth, strict=True)):17d}  "
            f"{negated:13d}  {sum(g == t for g, t in commands) / len(commands):8.3f}  "
            f"{heard / truth.count('stop'):13.3f}"
        )


if __name__ == "__main__":
    main()
