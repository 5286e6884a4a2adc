"""Checks on uploaded recordings: declared type, size, the file's own signature, length.

A recording is decoded (:func:`explaindrive.audio.decode_bounded`), frame by frame, to
16 kHz mono 16-bit samples and stored as a WAV file; decoding stops as soon as the audio
runs past :data:`MAX_AUDIO_S`, so a small file that expands to hours of audio (a FLAC of
constant level costs about ten bytes per second) never gets into memory whole. Nothing a
client sends (its file name in particular) reaches the file system.
"""

from __future__ import annotations

import io
import wave

import numpy as np
from numpy.typing import NDArray
from starlette.datastructures import UploadFile

from explaindrive.audio import (
    MAX_CHANNELS,
    MAX_INPUT_RATE_HZ,
    STORED_RATE_HZ,
    AudioRejectedError,
)
from explaindrive.audio import decode_bounded as _decode_bounded

__all__ = [
    "MAX_AUDIO_S",
    "MAX_CHANNELS",
    "MAX_INPUT_RATE_HZ",
    "STORED_RATE_HZ",
    "AudioRejectedError",
    "decode_bounded",
    "read_upload",
    "sniff",
    "wav_bytes",
]

CHUNK_BYTES = 64 * 1024
MAX_AUDIO_S = 30.0  # [s] a request is a sentence or two; Whisper reads 30 s windows

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
    """An upload's samples, at most :data:`MAX_AUDIO_S` of them
    (:func:`explaindrive.audio.decode_bounded`).

    Raises:
        AudioRejectedError: 413 when too long, 415 when undecodable, 422 when empty.
    """
    return _decode_bounded(data, max_duration_s)


def wav_bytes(samples: NDArray[np.int16], rate_hz: int = STORED_RATE_HZ) -> bytes:
    """16-bit mono WAV file content of ``samples``."""
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(rate_hz)
        out.writeframes(samples.astype("<i2").tobytes())
    return buffer.getvalue()
