"""The LLM-1 cascade: the MiniLM model answers, except for the requests it is least sure
of, which the mpnet model answers.

"Least sure" is a gap between its two most probable labels of at most the escalation
margin. The margin is tuned on the pooled held-out probabilities of the two shipped
models (each development split predicted by a model that did not see it, as in
:func:`explaindrive.language.intent_classifier.select`): it minimises the same weighted
error count as model selection, with at most ``ESCALATION_BUDGET`` of those requests
escalated, so nearly every request pays only for the small encoder. Rebuild with::

    python -m explaindrive.language.cascade
"""

from __future__ import annotations

import argparse
import json
import logging
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from explaindrive.language.datasets import (
    CASCADE_JSON,
    DEV_SPLITS,
    TRAIN_CSV,
    data_path,
    load_commands,
)
from explaindrive.language.encoders import EncoderName
from explaindrive.language.features import SentenceEncoder
from explaindrive.language.intent_classifier import (
    SELECTION_GRID,
    STOP,
    Encoded,
    IntentClassifier,
    decide_rows,
    select,
    selection_cost,
)

log = logging.getLogger(__name__)

ESCALATION_BUDGET = 0.04  # largest share of held-out requests sent to the large encoder
SMALL: EncoderName = "minilm"
LARGE: EncoderName = "mpnet"


def confidence_gap(p: NDArray[np.floating]) -> NDArray[np.float64]:
    """Per row, the most probable label's probability minus the second one's."""
    top2 = np.sort(np.asarray(p, dtype=np.float64), axis=1)[:, -2:]
    return top2[:, 1] - top2[:, 0]


def cascade_rows(
    gap_small: NDArray[np.floating],
    pred_small: NDArray[np.int64],
    pred_large: NDArray[np.int64],
    margin: float,
) -> NDArray[np.int64]:
    """Cascade labels: the large model's where the small one's gap is ``<= margin``."""
    return np.where(np.asarray(gap_small) <= margin, pred_large, pred_small).astype(np.int64)


def tune_escalation_margin(
    gap_small: NDArray[np.floating],
    pred_small: NDArray[np.int64],
    pred_large: NDArray[np.int64],
    y: NDArray[np.int64],
    budget: float = ESCALATION_BUDGET,
) -> float:
    """The margin (0.01 grid) with the lowest :func:`selection_cost` among those that
    escalate at most ``budget`` of the requests; the lowest such margin on ties."""
    best: tuple[float, float] | None = None  # (cost, margin)
    for m in np.round(np.arange(0.0, 1.0 + 1e-9, 0.01), 2):
        if np.mean(np.asarray(gap_small) <= m) > budget:
            break  # the share escalated only grows with the margin
        cost = selection_cost(cascade_rows(gap_small, pred_small, pred_large, float(m)), y)
        if best is None or cost < best[0]:
            best = (cost, float(m))
    return best[1] if best is not None else 0.0


@dataclass(frozen=True, slots=True)
class CascadeRule:
    """When the cascade escalates, with the held-out figures it was tuned on."""

    escalation_margin: float
    budget: float = ESCALATION_BUDGET
    held_out: dict[str, Any] | None = None

    def escalate(self, p_small: NDArray[np.floating]) -> bool:
        """Whether the small model's probability row ``p_small`` goes to the large one."""
        return bool(confidence_gap(np.atleast_2d(p_small))[0] <= self.escalation_margin)

    def save(self, path: str | Path) -> None:
        """Write the rule as JSON."""
        Path(path).write_text(json.dumps(asdict(self), indent=2) + "\n", encoding="utf-8")

    @classmethod
    def load(cls, path: str | Path | None = None) -> CascadeRule:
        """Read a rule (default: the shipped one).

        Raises:
            FileNotFoundError: if the file is missing.
            ValueError: if it is not a rule written by :meth:`save`.
        """
        p = Path(path) if path is not None else data_path(CASCADE_JSON)
        if not p.is_file():
            raise FileNotFoundError(f"cascade rule not found: {p}")
        try:
            raw = json.loads(p.read_text(encoding="utf-8"))
            margin = raw["escalation_margin"]
        except (json.JSONDecodeError, TypeError, KeyError) as exc:
            raise ValueError(f"{p}: not a cascade rule ({exc})") from exc
        if not isinstance(margin, int | float) or not 0.0 <= margin <= 1.0:
            raise ValueError(f"{p}: escalation_margin must be a number in [0, 1], got {margin!r}")
        return cls(float(margin), float(raw.get("budget", ESCALATION_BUDGET)), raw.get("held_out"))


def _held_out(
    name: EncoderName, train_rows: list[Any], dev_rows: list[list[Any]]
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """Pooled held-out probabilities, labels and decisions of the shipped ``name`` model.

    Raises:
        ValueError: if the shipped weights were not selected from these files.
    """
    clf = IntentClassifier.load(encoder=name)
    encoder = SentenceEncoder(name=name)
    train = Encoded.of(train_rows, encoder)
    devs = [Encoded.of(rows, encoder) for rows in dev_rows]
    grid = {
        "c": SELECTION_GRID["c"],
        "ngram_weight": (clf.spec.ngram_weight,),
        "cue_weight": (clf.spec.cue_weight,),
        "lr_weight": (clf.lr_weight,),
    }
    sel = select(train, devs, grid)
    if (sel.stop_threshold, sel.none_margin) != (clf.stop_threshold, clf.none_margin):
        raise ValueError(
            f"the shipped {name} weights were not built from these files (STOP threshold "
            f"{clf.stop_threshold} / none margin {clf.none_margin}, selection gives "
            f"{sel.stop_threshold} / {sel.none_margin}); rebuild them first"
        )
    y = np.concatenate([d.y for d in devs])
    return sel.proba, y, decide_rows(sel.proba, sel.stop_threshold, sel.none_margin)


def _figures(pred: NDArray[np.int64], y: NDArray[np.int64]) -> dict[str, float]:
    return {
        "accuracy": round(float(np.mean(pred == y)), 4),
        "cost": selection_cost(pred, y),
        "stop_recall": round(float(np.mean(pred[y == STOP] == STOP)), 4),
    }


def build(train_rows: list[Any], dev_rows: list[list[Any]]) -> CascadeRule:
    """Tune the escalation margin on the shipped models' pooled held-out predictions."""
    p_small, y, pred_small = _held_out(SMALL, train_rows, dev_rows)
    _, _, pred_large = _held_out(LARGE, train_rows, dev_rows)
    gap = confidence_gap(p_small)
    margin = tune_escalation_margin(gap, pred_small, pred_large, y)
    pred = cascade_rows(gap, pred_small, pred_large, margin)
    held_out = {
        "requests": len(y),
        "escalated": round(float(np.mean(gap <= margin)), 4),
        SMALL: _figures(pred_small, y),
        LARGE: _figures(pred_large, y),
        "cascade": _figures(pred, y),
    }
    log.info("escalation margin %.2f: %s", margin, held_out)
    return CascadeRule(margin, ESCALATION_BUDGET, held_out)


def main(argv: list[str] | None = None) -> None:
    """Re-tune the shipped cascade rule from the shipped data and weights."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=data_path(CASCADE_JSON))
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    train_rows = load_commands(data_path(TRAIN_CSV))
    dev_rows = [load_commands(data_path(n)) for n in DEV_SPLITS]
    build(train_rows, dev_rows).save(args.out)
    log.info("wrote %s", args.out)


if __name__ == "__main__":
    main()
