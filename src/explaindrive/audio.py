"""Audio decoded in bounded memory: the one decoder of ``transcribe``, ride scripts and the
web page's uploads.

A recording is read frame by frame and resampled to 16 kHz mono 16-bit samples; both the
decoded input and the output are counted as they come, and decoding stops at the first
frame past the caller's limit, so a file that holds (or expands to) hours of audio never
gets into memory whole: the peak is the limit's samples plus one frame.
"""

from __future__ import annotations

import io
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

MAX_INPUT_RATE_HZ = 192_000  # [Hz] highest sample rate accepted
MAX_CHANNELS = 8
STORED_RATE_HZ = 16_000  # [Hz] Whisper's input rate, the rate of the decoded samples


class AudioRejectedError(ValueError):
    """A recording that is not accepted; ``status_code`` is the HTTP status that says why
    (413 too long, 415 not decodable, 422 no samples)."""

    def __init__(self, message: str, status_code: int) -> None:
        super().__init__(message)
        self.status_code = status_code


def decode_bounded(source: bytes | Path, max_duration_s: float) -> NDArray[np.int16]:
    """Decode a recording (its bytes, or a file) to 16 kHz mono 16-bit samples, at most
    ``max_duration_s`` of it.

    The input is read frame by frame; both the decoded input (duration and samples per
    channel) and the resampled output are counted as they come, and decoding stops at the
    first frame past the limit. The container's declared duration is checked first.

    Raises:
        AudioRejectedError: 413 when the audio is longer than ``max_duration_s``, 415 when
            it cannot be decoded or has an unsupported layout, 422 when it holds no samples.
    """
    import av

    limit_out = int(max_duration_s * STORED_RATE_HZ)
    chunks: list[NDArray[np.int16]] = []
    n_out = 0
    try:
        with av.open(io.BytesIO(source) if isinstance(source, bytes) else str(source)) as container:
            stream = _audio_stream(container, max_duration_s)
            resampler = av.AudioResampler(format="s16", layout="mono", rate=STORED_RATE_HZ)
            for frame in _frames(container, stream, max_duration_s):
                for out in resampler.resample(frame):
                    n_out += out.samples
                    if n_out > limit_out:
                        raise _too_long(max_duration_s)
                    chunks.append(out.to_ndarray().reshape(-1).astype(np.int16, copy=False))
            for out in resampler.resample(None):
                chunks.append(out.to_ndarray().reshape(-1).astype(np.int16, copy=False))
    except AudioRejectedError:
        raise
    except Exception as exc:  # PyAV raises many types for bad input
        raise AudioRejectedError(f"the recording cannot be decoded: {_short(exc)}", 415) from exc
    samples = np.concatenate(chunks)[:limit_out] if chunks else np.zeros(0, np.int16)
    if samples.size == 0:
        raise AudioRejectedError("the recording holds no audio", 422)
    return samples


def _audio_stream(container: Any, max_duration_s: float) -> Any:
    """The first audio stream, checked for layout and declared length."""
    if not container.streams.audio:
        raise AudioRejectedError("the file holds no audio stream", 415)
    stream = container.streams.audio[0]
    rate, channels = stream.sample_rate or 0, stream.channels or 0
    if not 0 < rate <= MAX_INPUT_RATE_HZ or not 0 < channels <= MAX_CHANNELS:
        raise AudioRejectedError(
            f"unsupported audio layout ({rate} Hz, {channels} channels); at most "
            f"{MAX_INPUT_RATE_HZ} Hz and {MAX_CHANNELS} channels",
            415,
        )
    declared_us = container.duration  # [us] None when the container does not say
    if declared_us is not None and declared_us > max_duration_s * 1e6:
        raise _too_long(max_duration_s)
    return stream


def _frames(container: Any, stream: Any, max_duration_s: float) -> Iterator[Any]:
    """Decoded frames of ``stream``, stopped at the first one past ``max_duration_s``."""
    seconds = 0.0
    samples = 0  # per channel
    limit_samples = int(max_duration_s * MAX_INPUT_RATE_HZ)
    for frame in container.decode(stream):
        rate = frame.sample_rate or 0
        if not 0 < rate <= MAX_INPUT_RATE_HZ:
            raise AudioRejectedError(f"unsupported sample rate {rate} Hz", 415)
        samples += frame.samples
        seconds += frame.samples / rate
        if seconds > max_duration_s or samples > limit_samples:
            raise _too_long(max_duration_s)
        yield frame


def _too_long(max_duration_s: float) -> AudioRejectedError:
    return AudioRejectedError(
        f"the recording is longer than {max_duration_s:g} s; say the request in a sentence or two",
        413,
    )


def _short(exc: Exception) -> str:
    return str(exc)[:160]
