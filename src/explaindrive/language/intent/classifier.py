"""The embedded LLM-1 classifier at run time: logistic regression on sentence features
(embedding, word n-grams, direction cues), blended with a nearest-neighbour vote over the
training requests' embeddings.

STOP is safety-critical: it wins whenever its probability reaches the classifier's
``stop_threshold``. A request is off-topic only when its off-topic probability leads the
best command's by more than ``none_margin``. Both are stored with the weights, which
:mod:`explaindrive.language.intent.training` builds (and re-ships with
``python -m explaindrive.language.intent.training``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from explaindrive.language.data import CLASSIFIER_NPZ, data_path
from explaindrive.language.intent.datasets import INTENT_LABELS
from explaindrive.language.intent.encoders import ENCODER
from explaindrive.language.intent.features import FeatureSpec

STOP = INTENT_LABELS.index("stop")
NONE = INTENT_LABELS.index("none")
KNN_TEMPERATURE = 0.05  # softmax temperature over per-class best cosine similarities


@dataclass(frozen=True)
class IntentClassifier:
    """Linear softmax classifier over :data:`INTENT_LABELS` with decision thresholds."""

    coef: NDArray[np.float64]  # (4, n_features)
    intercept: NDArray[np.float64]  # (4,)
    ref_embeddings: NDArray[np.float32]  # (n_train, dim) unit-norm training embeddings
    ref_labels: NDArray[np.int64]  # (n_train,) indices into INTENT_LABELS
    stop_threshold: float
    none_margin: float
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
        none_margin: float | None = None,
    ) -> str:
        """Label for one probability row.

        ``stop`` when its probability reaches the STOP threshold; else ``none`` when the
        off-topic probability exceeds the best command's by more than the none margin;
        else the most probable command.
        """
        return INTENT_LABELS[
            int(
                decide_rows(
                    np.asarray(p, dtype=np.float64)[None, :],
                    self.stop_threshold if stop_threshold is None else stop_threshold,
                    self.none_margin if none_margin is None else none_margin,
                )[0]
            )
        ]

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
            none_margin=self.none_margin,
            hash_features=self.spec.hash_features,
            ngram_weight=self.spec.ngram_weight,
            cue_weight=self.spec.cue_weight,
            n_cues=self.spec.n_cues,
            encoder=self.spec.encoder,
            lr_weight=self.lr_weight,
        )

    @classmethod
    def load(cls, path: str | Path | None = None) -> IntentClassifier:
        """Read weights (default: the shipped ones).

        Raises:
            FileNotFoundError: if the file is missing.
            ValueError: if it is not a classifier written by :meth:`save`, or was built
                over another encoder's embeddings.
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
                    none_margin=float(z["none_margin"]),
                    spec=FeatureSpec(
                        int(z["hash_features"]),
                        float(z["ngram_weight"]),
                        float(z["cue_weight"]),
                        int(z["n_cues"]),
                        str(z["encoder"]) if "encoder" in z.files else ENCODER,
                    ),
                    lr_weight=float(z["lr_weight"]),
                )
        except (OSError, KeyError, ValueError) as exc:
            raise ValueError(f"{p}: not a valid intent classifier file ({exc})") from exc
        if labels != INTENT_LABELS:
            raise ValueError(f"{p}: labels {labels} differ from {INTENT_LABELS}")
        if clf.spec.encoder != ENCODER:
            raise ValueError(
                f"{p}: built over the {clf.spec.encoder!r} encoder's embeddings, not "
                f"{ENCODER!r}; rebuild with `python -m explaindrive.language.intent.training`"
            )
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


def decide_rows(
    p: NDArray[np.floating], stop_threshold: float, none_margin: float
) -> NDArray[np.int64]:
    """Label indices for probability rows (see :meth:`IntentClassifier.decide`)."""
    best = p[:, :NONE].argmax(axis=1)
    p_best = p[np.arange(len(p)), best]
    out = np.where(p[:, NONE] - p_best > none_margin, NONE, best)
    return np.where(p[:, STOP] >= stop_threshold, STOP, out).astype(np.int64)
