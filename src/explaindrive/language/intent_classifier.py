"""The embedded LLM-1 classifier: logistic regression on sentence features (embedding,
word n-grams, direction cues), blended with a nearest-neighbour vote over the training
requests' embeddings.

Protocol: the hyper-parameters (:class:`Hyper`: C, n-gram and cue weights, blend) are
chosen on the development split by a model fitted on the training split only; the shipped
model is then refitted on training + development requests. The held-out test split is
never read here.

STOP is safety-critical: it wins whenever its probability reaches ``stop_threshold``. The
threshold minimises a cost in which a missed STOP counts ``STOP_MISS_COST`` times a false
STOP on out-of-fold probabilities of training + development requests, capped so that every
development STOP request (out of fold) still reaches it. Retrain and re-ship the weights
with::

    python -m explaindrive.language.intent_classifier
"""

from __future__ import annotations

import argparse
import itertools
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import StratifiedKFold

from explaindrive.language.datasets import (
    CLASSIFIER_NPZ,
    DEV_CSV,
    INTENT_LABELS,
    TRAIN_CSV,
    CommandExample,
    data_path,
    load_commands,
)
from explaindrive.language.features import (
    FeatureSpec,
    SentenceEncoder,
    features_from_embeddings,
    normalize_text,
)

log = logging.getLogger(__name__)

STOP = INTENT_LABELS.index("stop")
NONE = INTENT_LABELS.index("none")
KNN_TEMPERATURE = 0.05  # softmax temperature over per-class best cosine similarities
STOP_MISS_COST = 5.0  # a missed STOP costs this many false STOPs when tuning the threshold
MAX_STOP_THRESHOLD = 0.5
MIN_STOP_THRESHOLD = 0.1


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


SELECTION_GRID: dict[str, tuple[float, ...]] = {
    "c": (10.0, 100.0),
    "ngram_weight": (1.0, 1.5),
    "cue_weight": (0.0, 0.5, 1.0, 2.0),
    "lr_weight": (0.35, 0.5, 0.75, 1.0),
}


@dataclass(frozen=True)
class IntentClassifier:
    """Linear softmax classifier over :data:`INTENT_LABELS` with decision thresholds."""

    coef: NDArray[np.float64]  # (4, n_features)
    intercept: NDArray[np.float64]  # (4,)
    ref_embeddings: NDArray[np.float32]  # (n_train, dim) unit-norm training embeddings
    ref_labels: NDArray[np.int64]  # (n_train,) indices into INTENT_LABELS
    stop_threshold: float
    none_threshold: float
    spec: FeatureSpec = field(default_factory=FeatureSpec)
    lr_weight: float = 0.5  # p = lr_weight * p_logreg + (1 - lr_weight) * p_knn

    def proba(self, x: NDArray[np.floating]) -> NDArray[np.float64]:
        """Class probabilities for feature rows ``x`` (``[embedding | n-grams]``)."""
        if x.ndim != 2 or x.shape[1] != self.coef.shape[1]:
            raise ValueError(f"expected features of width {self.coef.shape[1]}, got {x.shape}")
        p_lr = _softmax(x @ self.coef.T + self.intercept)
        dim = self.ref_embeddings.shape[1]
        if self.lr_weight >= 1.0:
            return p_lr
        p_knn = knn_proba(x[:, :dim], self.ref_embeddings, self.ref_labels)
        return self.lr_weight * p_lr + (1.0 - self.lr_weight) * p_knn

    def decide(
        self,
        p: NDArray[np.floating],
        stop_threshold: float | None = None,
        none_threshold: float | None = None,
    ) -> str:
        """Label for one probability row: ``stop`` first, then ``none``, then the argmax."""
        st = self.stop_threshold if stop_threshold is None else stop_threshold
        nt = self.none_threshold if none_threshold is None else none_threshold
        if p[STOP] >= st:
            return "stop"
        top = int(np.argmax(p))
        if top == NONE or p[top] < nt:
            return "none"
        return INTENT_LABELS[top]

    def save(self, path: str | Path) -> None:
        """Write the weights as ``.npz``."""
        np.savez_compressed(
            path,
            coef=self.coef,
            intercept=self.intercept,
            labels=np.array(INTENT_LABELS),
            ref_embeddings=self.ref_embeddings.astype(np.float16),
            ref_labels=self.ref_labels,
            stop_threshold=self.stop_threshold,
            none_threshold=self.none_threshold,
            hash_features=self.spec.hash_features,
            ngram_weight=self.spec.ngram_weight,
            cue_weight=self.spec.cue_weight,
            n_cues=self.spec.n_cues,
            lr_weight=self.lr_weight,
        )

    @classmethod
    def load(cls, path: str | Path | None = None) -> IntentClassifier:
        """Read weights (default: the shipped ones).

        Raises:
            FileNotFoundError: if the file is missing.
            ValueError: if it is not a classifier written by :meth:`save`.
        """
        p = Path(path) if path is not None else data_path(CLASSIFIER_NPZ)
        if not p.is_file():
            raise FileNotFoundError(f"intent classifier weights not found: {p}")
        try:
            with np.load(p, allow_pickle=False) as z:
                labels = tuple(str(x) for x in z["labels"])
                clf = cls(
                    coef=np.asarray(z["coef"], dtype=np.float64),
                    intercept=np.asarray(z["intercept"], dtype=np.float64),
                    ref_embeddings=np.asarray(z["ref_embeddings"], dtype=np.float32),
                    ref_labels=np.asarray(z["ref_labels"], dtype=np.int64),
                    stop_threshold=float(z["stop_threshold"]),
                    none_threshold=float(z["none_threshold"]),
                    spec=FeatureSpec(
                        int(z["hash_features"]),
                        float(z["ngram_weight"]),
                        float(z["cue_weight"]),
                        int(z["n_cues"]),
                    ),
                    lr_weight=float(z["lr_weight"]),
                )
        except (OSError, KeyError, ValueError) as exc:
            raise ValueError(f"{p}: not a valid intent classifier file ({exc})") from exc
        if labels != INTENT_LABELS:
            raise ValueError(f"{p}: labels {labels} differ from {INTENT_LABELS}")
        return clf


def _softmax(z: NDArray[np.floating]) -> NDArray[np.float64]:
    z = np.asarray(z, dtype=np.float64)
    z = z - z.max(axis=1, keepdims=True)
    e = np.exp(z)
    return np.asarray(e / e.sum(axis=1, keepdims=True), dtype=np.float64)


def knn_proba(
    emb: NDArray[np.floating], ref: NDArray[np.floating], ref_labels: NDArray[np.int64]
) -> NDArray[np.float64]:
    """Softmax over, per class, the best cosine similarity to a training request."""
    sims = np.asarray(emb, dtype=np.float32) @ np.asarray(ref, dtype=np.float32).T
    best = np.stack(
        [
            sims[:, ref_labels == k].max(axis=1)
            if (ref_labels == k).any()
            else np.full(len(sims), -1.0)
            for k in range(len(INTENT_LABELS))
        ],
        axis=1,
    )
    return _softmax(best / KNN_TEMPERATURE)


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
        none_threshold=0.0,
        spec=spec,
        lr_weight=hyper.lr_weight,
    )


def recall_stop_threshold(p_stop: NDArray[np.floating], is_stop: NDArray[np.bool_]) -> float:
    """Highest threshold on the 0.01 grid at which every STOP row still reaches it."""
    if not is_stop.any():
        return MAX_STOP_THRESHOLD
    t = np.floor(float(np.min(p_stop[is_stop])) * 100.0) / 100.0
    return float(np.clip(t, MIN_STOP_THRESHOLD, MAX_STOP_THRESHOLD))


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

    def features(self, spec: FeatureSpec) -> NDArray[np.float32]:
        return features_from_embeddings(self.emb, self.texts, spec)


@dataclass(frozen=True, slots=True)
class Selection:
    """Outcome of the hyper-parameter search on the development split."""

    hyper: Hyper
    dev_accuracy: float  # 4-class accuracy on dev (none included), train-only model
    dev_stop_threshold: float  # highest threshold keeping dev STOP recall at 1.0
    dev_false_stops: int


def select(train: Encoded, dev: Encoded, grid: dict[str, tuple[float, ...]]) -> Selection:
    """Pick the hyper-parameters whose train-only model is most accurate on dev.

    For each candidate the STOP threshold is the highest one that keeps STOP recall on
    dev at 1.0; ties go to fewer false STOPs, then to the earlier candidate in the grid.
    """
    dim = train.emb.shape[1]
    best: tuple[float, int, Selection] | None = None
    for c, ngram_w, cue_w in itertools.product(grid["c"], grid["ngram_weight"], grid["cue_weight"]):
        spec = FeatureSpec(ngram_weight=ngram_w, cue_weight=cue_w)
        x_tr, x_dev = train.features(spec), dev.features(spec)
        model = _fit(x_tr, train.y, c)
        for lr_w in grid["lr_weight"]:
            hyper = Hyper(c, ngram_w, cue_w, lr_w)
            clf = _classifier(model, x_tr, train.y, dim, spec, hyper)
            p = clf.proba(x_dev)
            t = recall_stop_threshold(p[:, STOP], dev.y == STOP)
            pred = np.array([INTENT_LABELS.index(clf.decide(row, t)) for row in p])
            acc = float(np.mean(pred == dev.y))
            false_stops = int(np.sum((pred == STOP) & (dev.y != STOP)))
            log.info(
                "C=%g ngram=%g cue=%g lr=%g: dev accuracy %.3f, threshold %.2f, false STOPs %d",
                c,
                ngram_w,
                cue_w,
                lr_w,
                acc,
                t,
                false_stops,
            )
            if best is None or (acc, -false_stops) > (best[0], best[1]):
                best = (acc, -false_stops, Selection(hyper, acc, t, false_stops))
    assert best is not None
    return best[2]


def fit_final(
    train: Encoded, dev: Encoded, hyper: Hyper, *, folds: int = 5, seed: int = 0
) -> IntentClassifier:
    """Fit on training + development requests; calibrate the STOP threshold out of fold.

    The threshold minimises ``STOP_MISS_COST * missed STOPs + false STOPs`` on 5-fold
    out-of-fold probabilities of all requests and is then lowered, if needed, so that every
    development STOP request (out of fold) reaches it.
    """
    spec = FeatureSpec(ngram_weight=hyper.ngram_weight, cue_weight=hyper.cue_weight)
    x = np.vstack([train.features(spec), dev.features(spec)])
    y = np.concatenate([train.y, dev.y])
    from_dev = np.r_[np.zeros(len(train.y), bool), np.ones(len(dev.y), bool)]
    dim = train.emb.shape[1]
    oof = np.zeros((len(y), len(INTENT_LABELS)))
    for tr, va in StratifiedKFold(folds, shuffle=True, random_state=seed).split(x, y):
        fold = _fit(x[tr], y[tr], hyper.c)
        oof[va] = _classifier(fold, x[tr], y[tr], dim, spec, hyper).proba(x[va])
    t_cost = tune_stop_threshold(oof[:, STOP], y == STOP)
    t_dev = recall_stop_threshold(oof[from_dev, STOP], y[from_dev] == STOP)
    stop_t = min(t_cost, t_dev)
    clf = _classifier(_fit(x, y, hyper.c), x, y, dim, spec, hyper, stop_t)
    pred = np.array([INTENT_LABELS.index(clf.decide(row)) for row in oof])
    log.info(
        "out-of-fold (train+dev) accuracy %.3f, STOP recall %.3f; stop threshold %.2f "
        "(cost %.2f, dev recall %.2f)",
        float(np.mean(pred == y)),
        float(np.mean(pred[y == STOP] == STOP)),
        stop_t,
        t_cost,
        t_dev,
    )
    return clf


def train(
    train_rows: list[CommandExample],
    dev_rows: list[CommandExample],
    encoder: SentenceEncoder,
    grid: dict[str, tuple[float, ...]] | None = None,
) -> tuple[IntentClassifier, Selection]:
    """Select hyper-parameters on dev, then fit the shipped model on train + dev."""
    tr, dev = Encoded.of(train_rows, encoder), Encoded.of(dev_rows, encoder)
    sel = select(tr, dev, grid or SELECTION_GRID)
    log.info(
        "selected %s: dev accuracy %.3f (train-only model), dev STOP threshold %.2f, "
        "false STOPs %d",
        sel.hyper,
        sel.dev_accuracy,
        sel.dev_stop_threshold,
        sel.dev_false_stops,
    )
    return fit_final(tr, dev, sel.hyper), sel


def main(argv: list[str] | None = None) -> None:
    """Retrain the shipped classifier from the shipped training and development splits."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--train", type=Path, default=data_path(TRAIN_CSV))
    parser.add_argument("--dev", type=Path, default=data_path(DEV_CSV))
    parser.add_argument("--out", type=Path, default=data_path(CLASSIFIER_NPZ))
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    train_rows, dev_rows = load_commands(args.train), load_commands(args.dev)
    clf, _ = train(train_rows, dev_rows, SentenceEncoder())
    clf.save(args.out)
    log.info("wrote %s (%d + %d examples)", args.out, len(train_rows), len(dev_rows))


if __name__ == "__main__":
    main()
