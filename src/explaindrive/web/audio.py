"""Checks on uploaded recordings: declared type, size, the file's own signature, length.

A recording is decoded here, frame by frame, to 16 kHz mono 16-bit samples and stored
as a WAV file; decoding stops as soon as the audio runs past :data:`MAX_AUDIO_S`, so a
small file that expands to hours of audio (a FLAC of constant level costs about ten
bytes per second) never gets into memory whole. Nothing a client sends (its file name
in particular) reaches the file system.
"""

from __future__ import annotations

import io
import wave
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray
from starlette.datastructures import UploadFile

CHUNK_BYTES = 64 * 1024
MAX_AUDIO_S = 30.0  # [s] a request is a sentence or two; Whisper reads 30 s windows
MAX_INPUT_RATE_HZ = 192_000  # [Hz] highest sample rate accepted in an upload
MAX_CHANNELS = 8
STORED_RATE_HZ = 16_000  # [Hz] Whisper's input rate, the rate of the stored WAV

# Declared MIME type (parameters stripped) -> the container it must be.
ALLOWED_TYPES: dict[str, str] = {
    "audio/webm": "webm",
    "video/webm": "webm",  # some browsers label audio-only WebM this way
    "audio/ogg": "ogg",
    "audio/wav": "wav",
    "audio/x-wav": "wav",
    "audio/wave": "wav",
    "audio/vnd.wave": "wav",
    "audio/flac": "flac",
    "audio/x-flac": "flac",
    "audio/mpeg": "mp3",
    "audio/mp4": "mp4",
    "audio/x-m4a": "mp4",
}


class AudioRejectedError(ValueError):
    """An upload that is not accepted; ``status_code`` is the HTTP status to answer with."""

    def __init__(self, message: str, status_code: int) -> None:
        super().__init__(message)
        self.status_code = status_code


def sniff(data: bytes) -> str | None:
    """The audio container of ``data`` from its first bytes, or ``None``."""
    if data[:4] == b"RIFF" and data[8:12] == b"WAVE":
        return "wav"
    if data[:4] == b"\x1a\x45\xdf\xa3":
        return "webm"
    if data[:4] == b"OggS":
        return "ogg"
    if data[:4] == b"fLaC":
        return "flac"
    if data[:3] == b"ID3" or (len(data) > 1 and data[0] == 0xFF and data[1] & 0xE0 == 0xE0):
        return "mp3"
    if data[4:8] == b"ftyp":
        return "mp4"
    return None


async def read_upload(upload: UploadFile, max_bytes: int) -> tuple[bytes, str]:
    """Read and check one uploaded recording.

    Args:
        upload: the multipart file part.
        max_bytes: the largest accepted size [B].

    Returns:
        The bytes and the suffix to store them under (``.wav``, ``.webm``...).

    Raises:
        AudioRejectedError: 415 for a type that is not audio or a body that is not the
            declared format, 413 when too large, 422 when empty.
    """
    declared = (upload.content_type or "").split(";")[0].strip().lower()
    container = ALLOWED_TYPES.get(declared)
    if container is None:
        allowed = ", ".join(sorted(ALLOWED_TYPES))
        raise AudioRejectedError(
            f"unsupported content type {declared or 'none'!r}; send one of: {allowed}", 415
        )
    chunks: list[bytes] = []
    size = 0
    while chunk := await upload.read(CHUNK_BYTES):
        size += len(chunk)
        if size > max_bytes:
            raise AudioRejectedError(f"the upload exceeds {max_bytes} bytes", 413)
        chunks.append(chunk)
    data = b"".join(chunks)
    if not data:
        raise AudioRejectedError("the recording is empty", 422)
    found = sniff(data)
    if found != container:
        what = f"a {found} file" if found else "not a recognised audio file"
        raise AudioRejectedError(f"declared {declared} but the content is {what}", 415)
    return data, f".{container}"


def decode_bounded(data: bytes, max_duration_s: float = MAX_AUDIO_S) -> NDArray[np.int16]:
    """Decode a recording to 16 kHz mono 16-bit samples, at most ``max_duration_s`` of it.

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
        with av.open(io.BytesIO(data), mode="r") as container:
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


def wav_bytes(samples: NDArray[np.int16], rate_hz: int = STORED_RATE_HZ) -> bytes:
    """16-bit mono WAV file content of ``samples``."""
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(rate_hz)
        out.writeframes(samples.astype("<i2").tobytes())
    return buffer.getvalue()
