"""LLM-1 at run time: the fine-tuned encoder, the reading head and STOP's explicit path."""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from explaindrive.language.intent.encoders import (
    DEFAULT_RUNTIME,
    EncoderRuntime,
    SentenceEncoder,
    minilm_model_dir,
)
from explaindrive.language.intent.model import STOP, IntentModel, Reading, Thresholds
from explaindrive.language.intent.stop_path import names_stop


class LineReader:
    """Reads passenger lines with the shipped (or a given) intent model.

    The fine-tuned encoder is built in the cache from the pinned all-MiniLM-L6-v2 and the
    model's adapters on first use, then runs on ONNX Runtime (or PyTorch).
    """

    def __init__(
        self,
        model_path: Path | None = None,
        base_dir: Path | None = None,
        threads: int | None = None,
        runtime: EncoderRuntime = DEFAULT_RUNTIME,
        command_threshold: float | None = None,
        stop_threshold: float | None = None,
        stop_path: bool = True,
        ask_stop: bool = True,
    ) -> None:
        """Args:
        model_path: an intent model file; ``None`` = the shipped one.
        base_dir: the encoder the adapters apply to; ``None`` = the packaged MiniLM.
        threads: encoding threads; ``None`` = the runtime's default.
        runtime: ``onnx`` or ``torch``.
        command_threshold: replaces the model's own command threshold.
        stop_threshold: replaces the model's own STOP threshold.
        stop_path: read :data:`~explaindrive.language.intent.stop_path.STOP_PHRASES` as
            STOP unless the model is sure of another reading.
        ask_stop: keep the model's band below the STOP threshold where the car asks
            whether to stop (:attr:`~explaindrive.language.intent.model.Thresholds.ask_stop`).

        Raises:
            FileNotFoundError, ValueError: for a missing or invalid model file.
        """
        self.model = IntentModel.load(model_path)
        own = self.model.thresholds
        self.thresholds = Thresholds(
            own.command if command_threshold is None else command_threshold,
            own.stop if stop_threshold is None else stop_threshold,
            own.ask_stop if ask_stop else None,
        )
        self.stop_path = stop_path
        self._base_dir = base_dir
        self._threads = threads
        self._runtime = runtime
        self._encoder: SentenceEncoder | None = None
        self._lock = threading.Lock()

    @property
    def loaded(self) -> bool:
        """Whether the fine-tuned encoder is loaded."""
        return self._encoder is not None

    def load(self) -> None:
        """Build (once) and load the fine-tuned encoder now rather than on first use.

        Raises:
            FileNotFoundError: if the packaged encoder is missing.
            ValueError: if its weights are not the ones the model was trained on.
        """
        with self._lock:
            if self._encoder is None:
                base = self._base_dir or minilm_model_dir()
                encoder = SentenceEncoder(
                    self.model.encoder_dir(base), self._threads, self._runtime
                )
                encoder.load()
                self._encoder = encoder

    def embed(self, texts: list[str]) -> NDArray[np.float32]:
        """The fine-tuned encoder's unit-norm embeddings of ``texts``."""
        self.load()
        assert self._encoder is not None
        return self._encoder.encode(texts)

    def read(self, texts: list[str]) -> list[Reading]:
        """The reading of each line (:meth:`IntentModel.decide` plus STOP's path)."""
        p = self.model.proba(self.embed(texts))
        return [self._decide(text, row) for text, row in zip(texts, p, strict=True)]

    def _decide(self, text: str, p: NDArray[np.float64]) -> Reading:
        reading = self.model.decide(p, self.thresholds)
        if reading.reading == "stop" or not self.stop_path or not names_stop(text):
            return reading
        others = [i for i in range(len(reading.p)) if i != STOP]
        sure_of_other = max(reading.p[i] for i in others) >= self.thresholds.command
        return reading if sure_of_other else Reading("stop", reading.p)
