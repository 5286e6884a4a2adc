"""Do LLM-1's encoder runtimes agree? ONNX Runtime against PyTorch on the calibration pool.

Usage::

    python scripts/compare_encoder_runtimes.py

Encodes every line of the calibration pool (:mod:`explaindrive.language.intent.corpus`)
with the fine-tuned encoder on both runtimes and prints the largest embedding difference,
the lowest cosine, and how many of the shipped model's readings differ between them.
"""

from __future__ import annotations

import argparse

import numpy as np

from explaindrive.language.intent.corpus import calibration_pool
from explaindrive.language.intent.reader import LineReader


def main() -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    texts = [e.text for e in calibration_pool()]
    readers = [LineReader(runtime="onnx"), LineReader(runtime="torch")]
    embeddings = [r.embed(texts) for r in readers]
    readings = [[x.reading for x in r.read(texts)] for r in readers]
    a, b = embeddings
    differ = sum(x != y for x, y in zip(*readings, strict=True))
    print(f"{len(texts)} lines of the calibration pool")
    print(f"max |onnx - torch| per component: {float(np.max(np.abs(a - b))):.2e}")
    print(f"lowest cosine: {float(np.min(np.sum(a * b, axis=1))):.7f}")
    print(f"readings that differ: {differ} of {len(texts)}")


if __name__ == "__main__":
    main()
