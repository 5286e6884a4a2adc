"""Upload checks: signatures, declared types, size limits."""

from __future__ import annotations

import asyncio
import io

import pytest
from starlette.datastructures import Headers, UploadFile

from explaindrive.web.audio import AudioRejectedError, read_upload, sniff

WAV = b"RIFF\x24\x00\x00\x00WAVEfmt " + bytes(28)


@pytest.mark.parametrize(
    ("head", "kind"),
    [
        (WAV, "wav"),
        (b"\x1a\x45\xdf\xa3\x01\x00", "webm"),
        (b"OggS\x00\x02", "ogg"),
        (b"fLaC\x00\x00", "flac"),
        (b"ID3\x04\x00", "mp3"),
        (b"\xff\xfb\x90\x00", "mp3"),
        (b"\x00\x00\x00\x18ftypM4A ", "mp4"),
        (b"RIFF\x24\x00\x00\x00AVI LIST", None),
        (b"#!/bin/sh\nrm -rf /", None),
        (b"", None),
    ],
)
def test_sniff(head, kind):
    assert sniff(head) == kind


def _upload(data: bytes, content_type: str) -> UploadFile:
    return UploadFile(io.BytesIO(data), headers=Headers({"content-type": content_type}))


def test_read_upload_picks_the_suffix_from_the_content():
    data, suffix = asyncio.run(read_upload(_upload(WAV, "audio/wav; codecs=1"), 1000))
    assert (data, suffix) == (WAV, ".wav")


@pytest.mark.parametrize(
    ("data", "content_type", "status", "words"),
    [
        (WAV, "text/plain", 415, "unsupported content type"),
        (WAV, "", 415, "'none'"),
        (b"\x1a\x45\xdf\xa3" + bytes(10), "audio/wav", 415, "a webm file"),
        (b"hello", "audio/ogg", 415, "not a recognised audio file"),
        (b"", "audio/wav", 422, "empty"),
        (WAV + bytes(2000), "audio/wav", 413, "exceeds 1000 bytes"),
    ],
)
def test_read_upload_rejects(data, content_type, status, words):
    with pytest.raises(AudioRejectedError) as err:
        asyncio.run(read_upload(_upload(data, content_type), 1000))
    assert err.value.status_code == status
    assert words in str(err.value)
