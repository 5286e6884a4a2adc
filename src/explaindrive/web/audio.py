"""Checks on uploaded recordings: declared type, size and the file's own signature.

The suffix of the stored file comes from the detected format, so nothing a
client sends (its file name in particular) reaches the file system.
"""

from __future__ import annotations

from starlette.datastructures import UploadFile

CHUNK_BYTES = 64 * 1024

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
