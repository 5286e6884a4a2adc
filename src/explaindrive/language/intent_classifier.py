"""The embedded LLM-1 classifier: logistic regression on sentence features, blended
with a nearest-neighbour vote over the training requests' embeddings.

Hyper-parameters (``DEFAULT_C``, ``NGRAM_WEIGHT``, ``KNN_TEMPERATURE``, ``LR_WEIGHT``) were
chosen by 5-fold cross-validation on the training split only.

STOP is safety-critical: it wins whenever its probability reaches ``stop_threshold``,
tuned on out-of-fold probabilities of the training split to minimise a cost in which a
missed STOP counts ``STOP_MISS_COST`` times a false STOP. Retrain and re-ship the weights with::

    python -m explaindrive.language.intent_classifier
"""

from __future__ import annotations

import argparse
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import StratifiedKFold

from explaindrive.language.datasets import (
    CLASSIFIER_NPZ,
    INTENT_LABELS,
    TRAIN_CSV,
    data_path,
    load_commands,
)
from explaindrive.language.features import FeatureSpec, SentenceEncoder, features

log = logging.getLogger(__name__)

STOP = INTENT_LABELS.index("stop")
NONE = INTENT_LABELS.index("none")
DEFAULT_C = 100.0  # inverse L2 strength of the logistic regression
KNN_TEMPERATURE = 0.05  # softmax temperature over per-class best cosine similarities
LR_WEIGHT = 0.5  # p = LR_WEIGHT * p_logreg + (1 - LR_WEIGHT) * p_knn
STOP_MISS_COST = 5.0  # a missed STOP costs this many false STOPs when tuning the threshold
MAX_STOP_THRESHOLD = 0.5
MIN_STOP_THRESHOLD = 0.1


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

    def proba(self, x: NDArray[np.floating]) -> NDArray[np.float64]:
        """Class probabilities for feature rows ``x`` (``[embedding | n-grams]``)."""
        if x.ndim != 2 or x.shape[1] != self.coef.shape[1]:
            raise ValueError(f"expected features of width {self.coef.shape[1]}, got {x.shape}")
        p_lr = _softmax(x @ self.coef.T + self.intercept)
        dim = self.ref_embeddings.shape[1]
        p_knn = knn_proba(x[:, :dim], self.ref_embeddings, self.ref_labels)
        return LR_WEIGHT * p_lr + (1.0 - LR_WEIGHT) * p_knn

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
                    spec=FeatureSpec(int(z["hash_features"]), float(z["ngram_weight"])),
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
    model = LogisticRegression(C=c, max_iter=2000, class_weight="balanced")
    model.fit(x, y)
    return model


def train(
    texts: list[str],
    labels: list[str],
    encoder: SentenceEncoder,
    *,
    c: float = DEFAULT_C,
    folds: int = 5,
    seed: int = 0,
) -> IntentClassifier:
    """Train on labelled requests and tune the STOP threshold by cross-validation.

    The STOP threshold is the one in [0.1, 0.5] (step 0.01) that minimises
    ``STOP_MISS_COST * missed STOPs + false STOPs`` on out-of-fold probabilities
    (ties: the lowest threshold).
    """
    spec = FeatureSpec()
    x = features(encoder, texts, spec)
    y = np.array([INTENT_LABELS.index(label) for label in labels], dtype=np.int64)
    dim = x.shape[1] - spec.hash_features
    oof = np.zeros((len(y), len(INTENT_LABELS)))
    for tr, va in StratifiedKFold(folds, shuffle=True, random_state=seed).split(x, y):
        fold = _fit(x[tr], y[tr], c)
        oof[va] = IntentClassifier(
            fold.coef_, fold.intercept_, x[tr, :dim], y[tr], MAX_STOP_THRESHOLD, 0.0, spec
        ).proba(x[va])
    stop_t = tune_stop_threshold(oof[:, STOP], y == STOP)
    model = _fit(x, y, c)
    clf = IntentClassifier(
        model.coef_.astype(np.float64),
        model.intercept_.astype(np.float64),
        ref_embeddings=x[:, :dim].copy(),
        ref_labels=y,
        stop_threshold=stop_t,
        none_threshold=0.0,
        spec=spec,
    )
    cv_pred = [clf.decide(row) for row in oof]
    cv_acc = float(np.mean([p == t for p, t in zip(cv_pred, labels, strict=True)]))
    log.info("cross-validated accuracy %.3f, stop threshold %.3f", cv_acc, stop_t)
    return clf


def main(argv: list[str] | None = None) -> None:
    """Retrain the shipped classifier from the shipped training split."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=data_path(TRAIN_CSV))
    parser.add_argument("--out", type=Path, default=data_path(CLASSIFIER_NPZ))
    parser.add_argument("--c", type=float, default=DEFAULT_C)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    rows = load_commands(args.data)
    clf = train([r.text for r in rows], [r.label for r in rows], SentenceEncoder(), c=args.c)
    clf.save(args.out)
    log.info("wrote %s (%d examples)", args.out, len(rows))


if __name__ == "__main__":
    main()
