"""How LLM-1's two decision settings trade errors, on held-out development requests.

Usage::

    python scripts/decision_tradeoffs.py [--runtime torch|onnx]

Rebuilds the held-out probabilities the shipped model's settings were tuned on (each
development split predicted by a model fitted on the training requests and the other
development splits, with the shipped model's blend, n-gram and cue weights, from the embeddings
of the builder's runtime by default), then prints, for
each STOP threshold, the missed and false STOPs, and, for each none margin (at the shipped
STOP threshold), the command requests left without a command, the off-topic requests
given a command and the 3-class accuracy. Both settings can be overridden in the config
(``embedded.stop_threshold``, ``embedded.none_margin``) without retraining.
"""

from __future__ import annotations

import argparse

import numpy as np
from rich.console import Console
from rich.table import Table

from explaindrive.language.data import TRAIN_CSV, data_path
from explaindrive.language.intent.classifier import NONE, STOP, IntentClassifier, decide_rows
from explaindrive.language.intent.datasets import load_commands, training_splits
from explaindrive.language.intent.encoders import RUNTIMES
from explaindrive.language.intent.features import SentenceEncoder
from explaindrive.language.intent.training import BUILD_RUNTIME, Encoded, Hyper, held_out_proba


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runtime", default=BUILD_RUNTIME, choices=RUNTIMES)
    args = parser.parse_args()
    shipped = IntentClassifier.load()
    spec = shipped.spec
    hyper = Hyper(
        ngram_weight=spec.ngram_weight, cue_weight=spec.cue_weight, lr_weight=shipped.lr_weight
    )
    encoder = SentenceEncoder(runtime=args.runtime)
    train_rows, dev_rows = training_splits(load_commands(data_path(TRAIN_CSV)))
    train = Encoded.of(train_rows, encoder)
    devs = [Encoded.of(rows, encoder) for rows in dev_rows]
    p = held_out_proba(train, devs, spec, hyper.c, hyper)
    y = np.concatenate([d.y for d in devs])
    commands = y != NONE
    console = Console()
    console.print(
        f"{len(y)} held-out development requests ({int(commands.sum())} "
        f"commands, {int((y == STOP).sum())} STOP); shipped STOP threshold "
        f"{shipped.stop_threshold:.2f}, none margin {shipped.none_margin:.2f}"
    )

    stop_table = Table(title="STOP threshold (none margin as shipped)")
    for col in ("threshold", "missed STOPs", "false STOPs", "3-class accuracy"):
        stop_table.add_column(col, justify="right")
    for t in np.round(np.arange(0.20, 0.51, 0.04), 2):
        pred = decide_rows(p, float(t), shipped.none_margin)
        stop_table.add_row(
            f"{t:.2f}",
            str(int(np.sum((y == STOP) & (pred != STOP)))),
            str(int(np.sum((y != STOP) & (pred == STOP)))),
            f"{np.mean(pred[commands] == y[commands]):.3f}",
        )
    console.print(stop_table)

    none_table = Table(title="none margin (STOP threshold as shipped)")
    for col in (
        "margin",
        "commands left without one",
        "off-topic given a command",
        "3-class accuracy",
    ):
        none_table.add_column(col, justify="right")
    for m in np.round(np.arange(0.0, 0.61, 0.05), 2):
        pred = decide_rows(p, shipped.stop_threshold, float(m))
        none_table.add_row(
            f"{m:.2f}",
            str(int(np.sum(commands & (pred == NONE)))),
            str(int(np.sum(~commands & (pred != NONE)))),
            f"{np.mean(pred[commands] == y[commands]):.3f}",
        )
    console.print(none_table)


if __name__ == "__main__":
    main()
