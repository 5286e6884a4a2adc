"""Upload checks: signatures, declared types, size limits, decoded length."""

from __future__ import annotations

import asyncio
import io

import numpy as np
import pytest
from starlette.datastructures import Headers, UploadFile

from explaindrive.web.audio import (
    AudioRejectedError,
    decode_bounded,
    read_upload,
    sniff,
    wav_bytes,
)

from .conftest import wav
from .flac import BLOCK_SAMPLES, flac_bomb

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


def test_decode_bounded_resamples_to_16_khz_mono():
    samples = decode_bounded(wav(2.0, amplitude=8000, rate_hz=44_100, channels=2))
    assert samples.dtype == np.int16 and samples.shape == (32_000,)
    assert 7_500 < int(np.abs(samples).max()) <= 8_100  # the tone keeps its level
    assert wav_bytes(samples)[:4] == b"RIFF" and len(wav_bytes(samples)) == 44 + 64_000


@pytest.mark.parametrize("declare_length", [False, True])
def test_decode_bounded_stops_at_the_limit(declare_length):
    # 21 frames are 28.7 s of audio, 22 frames 30.03 s
    kept = decode_bounded(flac_bomb(21, declare_length=declare_length))
    assert kept.shape == (21 * BLOCK_SAMPLES // 3,) and set(np.unique(kept)) == {8000}
    for frames in (22, 8000):
        with pytest.raises(AudioRejectedError) as err:
            decode_bounded(flac_bomb(frames, declare_length=declare_length))
        assert err.value.status_code == 413 and "longer than 30 s" in str(err.value)


@pytest.mark.parametrize(
    ("data", "status", "words"),
    [
        (wav(3.0), 413, "longer than 2 s"),
        (wav(0.5, rate_hz=384_000), 415, "unsupported audio layout (384000 Hz"),
        (wav(0.5, channels=10), 415, "10 channels"),
        (wav(0.0), 422, "holds no audio"),
        (WAV, 415, "cannot be decoded"),
        (b"fLaC" + bytes(100), 415, "cannot be decoded"),
    ],
)
def test_decode_bounded_rejects(data, status, words):
    with pytest.raises(AudioRejectedError) as err:
        decode_bounded(data, max_duration_s=2.0)
    assert err.value.status_code == status
    assert words in str(err.value)
