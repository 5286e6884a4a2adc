"""Building the embedded LLM-1 classifier: hyper-parameter selection and the final fit.

Protocol: the hyper-parameters (:class:`Hyper`: C, n-gram and cue weights, blend) are
chosen on the development splits (``dev-1`` ... ``dev-N`` in the ``split`` column of
``commands_train.csv``, see :mod:`explaindrive.language.intent.datasets`), each held out in turn
from a model fitted on the training requests and the other development splits; the
shipped model is then refitted on all of them. The test file is never read here.

STOP is safety-critical: it wins whenever its probability reaches ``stop_threshold``. The
threshold minimises a cost in which a missed STOP counts ``STOP_MISS_COST`` times a false
STOP, on the pooled held-out probabilities of the development requests. A request is
off-topic only when its off-topic probability leads the best command's by more than
``none_margin``, tuned on the same probabilities with a dropped command costing
``COMMAND_DROP_COST`` off-topic requests answered with a confirmation question. The
classifier itself is :class:`~explaindrive.language.intent.classifier.IntentClassifier`.
Retrain and re-ship the weights with::

    python -m explaindrive.language.intent.training
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from sklearn.linear_model import LogisticRegression

from explaindrive.language.data import CLASSIFIER_NPZ, TRAIN_CSV, data_path
from explaindrive.language.intent.classifier import (
    NONE,
    STOP,
    IntentClassifier,
    decide_rows,
    knn_proba,
)
from explaindrive.language.intent.datasets import (
    INTENT_LABELS,
    CommandExample,
    load_commands,
    training_splits,
)
from explaindrive.language.intent.encoders import RUNTIMES, EncoderRuntime
from explaindrive.language.intent.features import (
    FeatureSpec,
    SentenceEncoder,
    features_from_embeddings,
    normalize_text,
)

log = logging.getLogger(__name__)

BUILD_RUNTIME: EncoderRuntime = "torch"
"""The runtime whose embeddings the shipped weights were built from. ONNX embeddings agree
to float rounding, which can still move a tuned threshold by one grid step."""
STOP_MISS_COST = 5.0  # a missed STOP costs this many false STOPs when tuning the threshold
MAX_STOP_THRESHOLD = 0.5
MIN_STOP_THRESHOLD = 0.1
COMMAND_DROP_COST = 2.0  # a command request left without a command costs two off-topic
# requests given a confirmation question (which the passenger can decline)
MAX_NONE_MARGIN = 0.4


@dataclass(frozen=True, slots=True)
class Hyper:
    """Hyper-parameters of the classifier (chosen on the development split)."""

    c: float = 100.0
    """Inverse L2 strength of the logistic regression."""
    ngram_weight: float = 1.5
    """Scale of the l2-normalised word n-gram block."""
    cue_weight: float = 1.0
    """Scale of the direction-cue counts."""
    lr_weight: float = 0.5
    """Blend: ``p = lr_weight * p_logreg + (1 - lr_weight) * p_knn``."""


# C=10, no cues and a pure logistic regression (lr_weight 1) never came first on the
# held-out development splits, so the grid leaves them out.
SELECTION_GRID: dict[str, tuple[float, ...]] = {
    "c": (100.0,),
    "ngram_weight": (1.0, 1.5),
    "cue_weight": (1.0, 2.0, 3.0),
    "lr_weight": (0.35, 0.5, 0.75),
}


def tune_none_margin(p: NDArray[np.floating], y: NDArray[np.int64], stop_threshold: float) -> float:
    """Margin minimising ``COMMAND_DROP_COST * dropped commands + off-topic commands``.

    A dropped command is a request for a command answered with a request to rephrase; an
    off-topic command is an off-topic request answered with a confirmation question, which
    the passenger can decline. Lowest margin on ties.
    """
    grid = np.round(np.arange(0.0, MAX_NONE_MARGIN + 1e-9, 0.05), 2)
    is_none = y == NONE
    costs = []
    for m in grid:
        pred_none = decide_rows(p, stop_threshold, float(m)) == NONE
        costs.append(
            COMMAND_DROP_COST * np.sum(~is_none & pred_none) + np.sum(is_none & ~pred_none)
        )
    return float(grid[int(np.argmin(costs))])


def tune_stop_threshold(p_stop: NDArray[np.floating], is_stop: NDArray[np.bool_]) -> float:
    """Threshold minimising ``STOP_MISS_COST * misses + false alarms`` (lowest on ties)."""
    grid = np.round(np.arange(MIN_STOP_THRESHOLD, MAX_STOP_THRESHOLD + 1e-9, 0.01), 2)
    costs = [
        STOP_MISS_COST * np.sum(is_stop & (p_stop < t)) + np.sum(~is_stop & (p_stop >= t))
        for t in grid
    ]
    return float(grid[int(np.argmin(costs))])


def _fit(x: NDArray[np.float32], y: NDArray[np.int64], c: float) -> LogisticRegression:
    model = LogisticRegression(C=c, max_iter=3000, class_weight="balanced")
    model.fit(x, y)
    return model


def _classifier(
    model: LogisticRegression,
    x: NDArray[np.float32],
    y: NDArray[np.int64],
    dim: int,
    spec: FeatureSpec,
    hyper: Hyper,
    stop_threshold: float = MAX_STOP_THRESHOLD,
) -> IntentClassifier:
    return IntentClassifier(
        model.coef_.astype(np.float64),
        model.intercept_.astype(np.float64),
        ref_embeddings=x[:, :dim].copy(),
        ref_labels=y.copy(),
        stop_threshold=stop_threshold,
        none_margin=0.0,
        spec=spec,
        lr_weight=hyper.lr_weight,
    )


@dataclass(frozen=True, slots=True)
class Encoded:
    """Labelled requests with their sentence embeddings (computed once)."""

    texts: list[str]
    y: NDArray[np.int64]
    emb: NDArray[np.float32]

    @classmethod
    def of(cls, rows: list[CommandExample], encoder: SentenceEncoder) -> Encoded:
        texts = [r.text for r in rows]
        y = np.array([INTENT_LABELS.index(r.label) for r in rows], dtype=np.int64)
        return cls(texts, y, encoder.encode([normalize_text(t) for t in texts]))

    @classmethod
    def concat(cls, parts: list[Encoded]) -> Encoded:
        return cls(
            [t for p in parts for t in p.texts],
            np.concatenate([p.y for p in parts]),
            np.vstack([p.emb for p in parts]),
        )

    def features(self, spec: FeatureSpec) -> NDArray[np.float32]:
        return features_from_embeddings(self.emb, self.texts, spec)


@dataclass(frozen=True, slots=True)
class Selection:
    """Outcome of the hyper-parameter search over the development splits."""

    hyper: Hyper
    accuracy: float  # 4-class accuracy on the pooled held-out development requests
    stop_threshold: float  # cost-tuned on the pooled held-out STOP probabilities
    none_margin: float  # cost-tuned on the pooled held-out probabilities
    stop_recall: float
    false_stops: int


def held_out_proba(
    train: Encoded, devs: list[Encoded], spec: FeatureSpec, c: float, hyper: Hyper
) -> NDArray[np.float64]:
    """Probabilities of every development request from a model that did not see its split.

    Split ``k`` is predicted by a model fitted on the training requests and the other
    development splits; the rows come back in the order of ``devs``.
    """
    dim = train.emb.shape[1]
    x_train, x_devs = train.features(spec), [d.features(spec) for d in devs]  # once per split
    out = []
    for k in range(len(devs)):
        x_fit = np.vstack([x_train, *(x for j, x in enumerate(x_devs) if j != k)])
        y_fit = np.concatenate([train.y, *(d.y for j, d in enumerate(devs) if j != k)])
        clf = _classifier(_fit(x_fit, y_fit, c), x_fit, y_fit, dim, spec, hyper)
        out.append(clf.proba(x_devs[k]))
    return np.vstack(out)


def held_out_knn_proba(train: Encoded, devs: list[Encoded]) -> NDArray[np.float64]:
    """The nearest-neighbour vote for every development request, over the training requests
    and the other development splits (rows in the order of ``devs``)."""
    out = []
    for k, held in enumerate(devs):
        ref = Encoded.concat([train, *(d for j, d in enumerate(devs) if j != k)])
        out.append(knn_proba(held.emb, ref.emb, ref.y))
    return np.vstack(out)


def selection_cost(pred: NDArray[np.int64], y: NDArray[np.int64]) -> float:
    """Errors of a candidate, a missed STOP weighing ``STOP_MISS_COST`` errors (as in the
    STOP threshold's own cost) and any other error one."""
    missed_stops = np.sum((y == STOP) & (pred != STOP))
    return float(np.sum(pred != y) + (STOP_MISS_COST - 1.0) * missed_stops)


def select(train: Encoded, devs: list[Encoded], grid: dict[str, tuple[float, ...]]) -> Selection:
    """Pick the hyper-parameters with the fewest errors on held-out development splits.

    Each development split is predicted by a model fitted on the training requests and
    the other development splits (leave one split out), so every split is judged by a
    model that never saw it. For each candidate the
    STOP threshold is tuned on the pooled held-out probabilities
    (:func:`tune_stop_threshold`); the candidate with the lowest :func:`selection_cost` at
    its threshold wins (ties: fewer false STOPs, then earlier in the grid).
    """
    y = np.concatenate([d.y for d in devs])
    p_knn = held_out_knn_proba(train, devs)  # depends on the embeddings only
    best: tuple[float, int, Selection] | None = None  # (cost, false STOPs, selection)
    for c, ngram_w, cue_w in itertools.product(grid["c"], grid["ngram_weight"], grid["cue_weight"]):
        spec = FeatureSpec(ngram_weight=ngram_w, cue_weight=cue_w)
        # the logistic regression does not depend on the blend: fit once, blend after
        p_lr = held_out_proba(train, devs, spec, c, Hyper(c, ngram_w, cue_w, 1.0))
        for lr_w in grid["lr_weight"]:
            hyper = Hyper(c, ngram_w, cue_w, lr_w)
            p = lr_w * p_lr + (1.0 - lr_w) * p_knn
            t = tune_stop_threshold(p[:, STOP], y == STOP)
            m = tune_none_margin(p, y, t)
            pred = decide_rows(p, t, m)
            acc = float(np.mean(pred == y))
            false_stops = int(np.sum((pred == STOP) & (y != STOP)))
            recall = float(np.mean(pred[y == STOP] == STOP))
            cost = selection_cost(pred, y)
            log.info(
                "C=%g ngram=%g cue=%g lr=%g: held-out accuracy %.3f, STOP threshold %.2f "
                "(recall %.3f, false STOPs %d), none margin %.2f, cost %g",
                c,
                ngram_w,
                cue_w,
                lr_w,
                acc,
                t,
                recall,
                false_stops,
                m,
                cost,
            )
            if best is None or (cost, false_stops) < (best[0], best[1]):
                best = (cost, false_stops, Selection(hyper, acc, t, m, recall, false_stops))
    assert best is not None
    return best[2]


def fit_final(train: Encoded, devs: list[Encoded], sel: Selection) -> IntentClassifier:
    """Fit the shipped model on the training and all development requests."""
    hyper = sel.hyper
    spec = FeatureSpec(ngram_weight=hyper.ngram_weight, cue_weight=hyper.cue_weight)
    pool = Encoded.concat([train, *devs])
    x = pool.features(spec)
    dim = train.emb.shape[1]
    clf = _classifier(_fit(x, pool.y, hyper.c), x, pool.y, dim, spec, hyper, sel.stop_threshold)
    return dataclasses.replace(clf, none_margin=sel.none_margin)


def train(
    train_rows: list[CommandExample],
    dev_splits: list[list[CommandExample]],
    encoder: SentenceEncoder,
    grid: dict[str, tuple[float, ...]] | None = None,
) -> tuple[IntentClassifier, Selection]:
    """Select hyper-parameters and the STOP threshold on the development splits (leave one
    split out), then fit the shipped model on everything."""
    if len(dev_splits) < 2:
        raise ValueError("selection needs at least two development splits")
    tr = Encoded.of(train_rows, encoder)
    devs = [Encoded.of(rows, encoder) for rows in dev_splits]
    sel = select(tr, devs, grid or SELECTION_GRID)
    log.info(
        "selected %s: held-out accuracy %.3f, STOP threshold %.2f (recall %.3f, false STOPs "
        "%d), none margin %.2f",
        sel.hyper,
        sel.accuracy,
        sel.stop_threshold,
        sel.stop_recall,
        sel.false_stops,
        sel.none_margin,
    )
    return fit_final(tr, devs, sel), sel


def main(argv: list[str] | None = None) -> None:
    """Retrain the shipped classifier from the training and development splits of the
    shipped ``commands_train.csv``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--data",
        type=Path,
        default=data_path(TRAIN_CSV),
        help="command CSV with a split column (train, dev-1 ... dev-N, reserve; at least "
        "two development splits, each held out in turn)",
    )
    parser.add_argument(
        "--runtime",
        choices=RUNTIMES,
        default=BUILD_RUNTIME,
        help="encoder runtime of the training embeddings (default: the one the shipped "
        "weights were built with)",
    )
    parser.add_argument(
        "--out", type=Path, default=None, help="weights file (default: the shipped one)"
    )
    args = parser.parse_args(argv)
    out = args.out or data_path(CLASSIFIER_NPZ)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    train_rows, dev_rows = training_splits(load_commands(args.data))
    clf, _ = train(train_rows, dev_rows, SentenceEncoder(runtime=args.runtime))
    clf.save(out)
    log.info(
        "wrote %s (%d training + %d development requests)",
        out,
        len(train_rows),
        sum(map(len, dev_rows)),
    )


if __name__ == "__main__":
    main()
