"""Do LLM-1's encoder runtimes agree? ONNX Runtime against PyTorch on the shipped data.

Usage::

    python scripts/compare_encoder_runtimes.py

Encodes every request of the development and reserve splits of ``commands_train.csv``
and of ``commands_test.csv`` with both runtimes and prints
the largest embedding difference, the lowest cosine, whether the token ids agree, and how
many of the shipped classifier's decisions differ between the runtimes.
"""

from __future__ import annotations

import argparse

import numpy as np

from explaindrive.language.data import TEST_CSV, TRAIN_CSV, data_path
from explaindrive.language.intent.classifier import IntentClassifier, decide_rows
from explaindrive.language.intent.datasets import TRAIN_SPLIT, load_commands
from explaindrive.language.intent.features import (
    SentenceEncoder,
    features_from_embeddings,
    normalize_text,
)


def main() -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    rows = load_commands(data_path(TRAIN_CSV)) + load_commands(data_path(TEST_CSV))
    texts = [r.text for r in rows if r.split != TRAIN_SPLIT]
    normalized = [normalize_text(t) for t in texts]
    onnx = SentenceEncoder(runtime="onnx")
    torch = SentenceEncoder(runtime="torch")
    a, b = onnx.encode(normalized), torch.encode(normalized)
    runner = onnx._onnx
    torch.load()
    prepare = getattr(torch._model, "preprocess", None) or torch._model.tokenize
    same_tokens = runner is not None and all(
        runner.tokens([t])["input_ids"][0].tolist() == prepare([t])["input_ids"][0].tolist()
        for t in normalized
    )
    clf = IntentClassifier.load()
    decide = [
        decide_rows(
            clf.proba(features_from_embeddings(e, texts, clf.spec)),
            clf.stop_threshold,
            clf.none_margin,
        )
        for e in (a, b)
    ]
    differ = int(np.sum(decide[0] != decide[1]))
    print(f"{len(texts)} requests outside the training split")
    print(f"max |onnx - torch| per component: {float(np.max(np.abs(a - b))):.2e}")
    print(f"lowest cosine: {float(np.min(np.sum(a * b, axis=1))):.7f}")
    print(f"token ids identical: {same_tokens}")
    print(f"shipped classifier decisions that differ: {differ} of {len(texts)}")


if __name__ == "__main__":
    main()
