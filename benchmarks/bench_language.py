"""Latency of the language layer: interpret, decide, explain per backend; Whisper's RTF.

Usage::

    python benchmarks/bench_language.py [--backend embedded|openai] [--n 200]
        [--runtime onnx|torch]

Prints p50/p95 latencies [ms] after model load and Whisper tiny.en's real-time factor
on espeak-ng speech (skipped when espeak-ng is missing). Targets on 2 cores: embedded
decide+explain p95 <= 5 ms, interpret p95 <= 30 ms, Whisper real-time factor <= 0.5.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from explaindrive.language.config import LanguageConfig
from explaindrive.language.data import DECISIONS_JSONL, TEST_CSV, data_path
from explaindrive.language.explanation.datasets import load_decisions
from explaindrive.language.intent.datasets import load_commands
from explaindrive.language.intent.encoders import DEFAULT_RUNTIME, RUNTIMES, encoder_threads
from explaindrive.language.stack import make_language_stack

SENTENCES = (
    "Please drive faster, I am late for my meeting.",
    "Could you slow down a little, I feel sick.",
    "Stop the car here, please.",
)


def pct(values: list[float]) -> tuple[float, float]:
    """p50 and p95 in milliseconds."""
    arr = np.asarray(values) * 1000.0
    return float(np.percentile(arr, 50)), float(np.percentile(arr, 95))


def main() -> None:
    parser = argparse.ArgumentParser(description="language-layer latency benchmark")
    parser.add_argument("--backend", default="embedded", choices=("embedded", "openai"))
    parser.add_argument("--n", type=int, default=200, help="requests / records timed")
    parser.add_argument(
        "--runtime", default=DEFAULT_RUNTIME, choices=RUNTIMES, help="LLM-1 encoder runtime"
    )
    args = parser.parse_args()
    console = Console()
    config = LanguageConfig().with_runtime(args.runtime)
    stack = make_language_stack(args.backend, config)
    t0 = time.perf_counter()
    stack.interpreter.interpret("warm up")  # loads the encoder
    load_s = time.perf_counter() - t0

    texts = [r.text for r in load_commands(data_path(TEST_CSV))]  # requests it never saw
    records = [r.record() for r in load_decisions(data_path(DECISIONS_JSONL))]
    lat_i = []
    for k in range(args.n):
        t = time.perf_counter()
        stack.interpreter.interpret(texts[k % len(texts)])
        lat_i.append(time.perf_counter() - t)
    lat_d, lat_de = [], []
    for k in range(args.n):
        rec = records[k % len(records)]
        t = time.perf_counter()
        d = stack.decider.decide(rec)
        lat_d.append(time.perf_counter() - t)
        if d.explain:
            stack.explainer.explain(rec, d.factor)
        lat_de.append(time.perf_counter() - t)

    threads = encoder_threads(args.runtime, config.embedded.encoder_threads)
    table = Table(
        title=f"language layer, backend {args.backend}, all-MiniLM-L6-v2 on "
        f"{args.runtime}, {threads} threads (load {load_s:.1f} s)"
    )
    for col in ("call", "n", "p50 [ms]", "p95 [ms]"):
        table.add_column(col, justify="right")
    for name, lat in (("interpret", lat_i), ("decide", lat_d), ("decide+explain", lat_de)):
        p50, p95 = pct(lat)
        table.add_row(name, str(len(lat)), f"{p50:.3f}", f"{p95:.3f}")
    console.print(table)

    espeak = shutil.which("espeak-ng")
    if espeak is None:
        console.print("espeak-ng not installed: Whisper real-time factor skipped")
        return
    stack.transcriber.load()
    with tempfile.TemporaryDirectory() as tmp:
        rtfs = []
        for i, sentence in enumerate(SENTENCES * 2):
            wav = Path(tmp) / f"s{i}.wav"
            subprocess.run([espeak, "-s", "150", "-w", str(wav), sentence], check=True)
            tr = stack.transcriber.transcribe(wav)
            rtfs.append(tr.real_time_factor)
    console.print(
        f"Whisper tiny.en real-time factor over {len(rtfs)} clips: "
        f"median {np.median(rtfs):.3f}, max {max(rtfs):.3f}"
    )


if __name__ == "__main__":
    main()
