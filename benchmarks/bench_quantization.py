"""Would int8 make LLM-1's encoder fast enough? Speed and embedding drift of quantized exports.

Usage::

    python benchmarks/bench_quantization.py [--encoder minilm|mpnet] [--n 150]

Quantizes the cached ONNX export of the encoder with ONNX Runtime's dynamic int8
quantization, once with every weight matrix product and once with the feed-forward output
projections left in full precision, and prints, next to the full-precision export, the
p50/p95 time of one request and the cosine of each embedding to the full-precision one on
held-out requests. The products of two activations (attention scores) are never quantized.
Nothing in the package uses the quantized files; they live in a temporary folder.
"""

from __future__ import annotations

import argparse
import re
import tempfile
import time
from pathlib import Path

import numpy as np
import onnx
import onnxruntime as ort
from onnxruntime.quantization import QuantType, quantize_dynamic
from rich.console import Console
from rich.table import Table

from explaindrive.cache import cache_dir
from explaindrive.language.datasets import TEST_CSV, data_path, load_commands
from explaindrive.language.encoders import (
    DEFAULT_ENCODER,
    ENCODERS,
    encoder_model_dir,
)
from explaindrive.language.features import normalize_text
from explaindrive.language.onnx_encoder import OnnxSentenceRunner, onnx_model_file


def time_session(path: Path, feeds: list[dict[str, np.ndarray]]) -> tuple[list[float], np.ndarray]:
    """Per-request seconds and embeddings of ``feeds`` on the export at ``path``."""
    options = ort.SessionOptions()
    options.intra_op_num_threads = 2
    session = ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
    session.run(None, feeds[0])
    times, out = [], []
    for feed in feeds:
        t = time.perf_counter()
        (emb,) = session.run(None, feed)
        times.append(time.perf_counter() - t)
        out.append(emb[0])
    return times, np.asarray(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--encoder", default=DEFAULT_ENCODER, choices=ENCODERS)
    parser.add_argument("--n", type=int, default=150, help="held-out requests timed")
    args = parser.parse_args()
    model_dir = encoder_model_dir(args.encoder)
    source = onnx_model_file(model_dir, cache_dir(), args.encoder)
    runner = OnnxSentenceRunner(source, model_dir, threads=2)
    texts = [normalize_text(r.text) for r in load_commands(data_path(TEST_CSV))][: args.n]
    feeds = [runner.tokens([t]) for t in texts]
    matmuls = [
        n.name
        for n in onnx.load(str(source), load_external_data=False).graph.node
        if n.op_type == "MatMul"
    ]
    # products of two activations (attention scores and their weighted values)
    scores = [n for n in matmuls if "attn/MatMul" in n or "attention/self/MatMul" in n]
    ffn_out = [n for n in matmuls if re.search(r"layer\.\d+/output/dense/MatMul$", n)]
    table = Table(
        title=f"{args.encoder}: dynamic int8 quantization, 2 threads, {len(texts)} requests"
    )
    for col in ("export", "p50 [ms]", "p95 [ms]", "cosine mean", "cosine min"):
        table.add_column(col, justify="right")
    base_times, base = time_session(source, feeds)
    with tempfile.TemporaryDirectory() as tmp:
        variants = {"full precision": (source, base_times, base)}
        for name, exclude in (
            ("int8, all weight products", scores),
            ("int8, feed-forward output in fp32", scores + ffn_out),
        ):
            out = Path(tmp) / f"{len(variants)}.onnx"
            quantize_dynamic(
                str(source), str(out), weight_type=QuantType.QInt8, nodes_to_exclude=exclude
            )
            times, emb = time_session(out, feeds)
            variants[name] = (out, times, emb)
        for name, (_, times, emb) in variants.items():
            cos = np.sum(emb * base, axis=1) / (
                np.linalg.norm(emb, axis=1) * np.linalg.norm(base, axis=1)
            )
            ms = np.asarray(times) * 1000.0
            table.add_row(
                name,
                f"{np.percentile(ms, 50):.1f}",
                f"{np.percentile(ms, 95):.1f}",
                f"{cos.mean():.4f}",
                f"{cos.min():.4f}",
            )
    Console().print(table)


if __name__ == "__main__":
    main()
