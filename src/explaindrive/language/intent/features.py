"""Sentence features for the embedded LLM-1: sentence embeddings (all-MiniLM-L6-v2, see
:mod:`explaindrive.language.intent.encoders`), hashed word n-grams and lexical direction cues.

The embedding carries meaning ("I'm late" ~ faster); the hashed n-grams carry short
phrases; the cues (:mod:`explaindrive.language.intent.cues`) make direction and negation
explicit, which embeddings blur ("go a bit slower" ~ "go a bit faster"; "stop speeding"
is comfort, not stop).
"""

from __future__ import annotations

import logging
import os
import re
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from sklearn.feature_extraction.text import HashingVectorizer

from explaindrive.cache import cache_dir
from explaindrive.language.intent.cues import N_CUES, cue_features
from explaindrive.language.intent.encoders import (
    DEFAULT_RUNTIME,
    ENCODER,
    EncoderRuntime,
    check_runtime,
    encoder_threads,
    minilm_model_dir,
)
from explaindrive.language.intent.onnx_encoder import OnnxSentenceRunner, onnx_model_file

log = logging.getLogger(__name__)

HASH_FEATURES = 2**12
NGRAM_WEIGHT = 1.5  # scale of the (l2-normalised) n-gram block next to the unit embedding
CUE_WEIGHT = 1.0  # scale of the cue counts
ENCODE_BATCH = 64  # sentences per forward pass


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


_hasher = HashingVectorizer(
    n_features=HASH_FEATURES,
    ngram_range=(1, 2),
    alternate_sign=False,
    binary=True,
    norm="l2",
    token_pattern=r"(?u)\b[\w']+\b",
)


def normalize_text(text: str) -> str:
    """Lower-case, unify apostrophes and squeeze white space."""
    t = text.lower().replace("\u2019", "'")
    return re.sub(r"\s+", " ", t).strip()


def ngram_features(texts: list[str]) -> NDArray[np.float32]:
    """Hashed binary word 1-2-grams, l2-normalised, shape ``(n, HASH_FEATURES)``."""
    m = _hasher.transform([normalize_text(t) for t in texts])
    return np.asarray(m.toarray(), dtype=np.float32)


@dataclass(frozen=True, slots=True)
class FeatureSpec:
    """How features were built, stored with the weights so they are rebuilt identically."""

    hash_features: int = HASH_FEATURES
    ngram_weight: float = NGRAM_WEIGHT
    cue_weight: float = CUE_WEIGHT
    n_cues: int = N_CUES
    encoder: str = ENCODER
    """The sentence encoder whose embeddings lead the feature row."""


def features(
    encoder: SentenceEncoder, texts: list[str], spec: FeatureSpec = FeatureSpec()
) -> NDArray[np.float32]:
    """The classifier's input: ``[embedding | ngram_weight * ngrams | cue_weight * cues]``."""
    return features_from_embeddings(encoder.encode([normalize_text(t) for t in texts]), texts, spec)


def features_from_embeddings(
    emb: NDArray[np.float32], texts: list[str], spec: FeatureSpec = FeatureSpec()
) -> NDArray[np.float32]:
    """:func:`features` for texts whose embeddings ``emb`` are already computed.

    Raises:
        ValueError: if ``spec`` was built by a different feature layout (retrain).
    """
    if spec.hash_features != HASH_FEATURES or spec.n_cues != N_CUES:
        raise ValueError(
            f"classifier expects {spec.hash_features} hashed features and {spec.n_cues} cues, "
            f"this code builds {HASH_FEATURES} and {N_CUES}; retrain with "
            "`python -m explaindrive.language.intent.training`"
        )
    return np.hstack(
        [emb, spec.ngram_weight * ngram_features(texts), spec.cue_weight * cue_features(texts)]
    ).astype(np.float32)
