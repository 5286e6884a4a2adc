"""Fixtures for the web tests: the app over fake language modules and a scripted driver."""

from __future__ import annotations

import io
import time
import wave
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest
from fastapi.testclient import TestClient

from explaindrive.language.speech.transcriber import Transcript
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.web import create_app

from ..ride.fakes import ScriptedController, fake_language

STEP_PERIOD_S = 0.05  # [s] twenty control steps per second of wall time
TEST_HOST = "testserver"  # the Host header of Starlette's test client
TEST_ORIGIN = f"http://{TEST_HOST}"


def wav(seconds: float, amplitude: int = 8000, rate_hz: int = 16_000, channels: int = 1) -> bytes:
    """A WAV file of a 440 Hz tone (``amplitude`` 0 gives silence)."""
    t = np.arange(int(seconds * rate_hz)) / rate_hz
    tone = (amplitude * np.sin(2 * np.pi * 440.0 * t)).astype("<i2")
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(channels)
        out.setsampwidth(2)
        out.setframerate(rate_hz)
        out.writeframes(np.repeat(tone, channels).tobytes())
    return buffer.getvalue()


class UploadTranscriber:
    """Stands in for Whisper: a loud recording 'says' it is in a hurry, a quiet one nothing.

    The files it was given are listed in ``seen`` (name, size in bytes, duration in s).
    """

    seen: ClassVar[list[tuple[str, int, float]]] = []

    def load(self) -> None:
        pass

    def transcribe(self, path: str | Path) -> Transcript:
        with wave.open(str(path), "rb") as audio:
            rate, frames = audio.getframerate(), audio.readframes(audio.getnframes())
        samples = np.frombuffer(frames, dtype="<i2")
        UploadTranscriber.seen.append(
            (Path(path).name, Path(path).stat().st_size, samples.size / rate)
        )
        loud = samples.size > 0 and int(np.abs(samples).max()) > 1000
        return Transcript("please hurry" if loud else "", samples.size / rate, 0.0, "en")


def fake_session_factory(config: RideConfig) -> RideSession:
    """A ride over live SUMO with the rule-based driver and keyword language modules."""
    language = replace(fake_language(), transcriber=UploadTranscriber())
    return RideSession(config, ScriptedController(), language)


@pytest.fixture
def client() -> Iterator[TestClient]:
    UploadTranscriber.seen.clear()
    app = create_app(
        fake_session_factory,
        step_period_s=STEP_PERIOD_S,
        max_upload_bytes=64_000,
        hosts=(TEST_HOST,),
    )
    with TestClient(app) as c:
        yield c


def wait_for(
    receive: Callable[[], dict[str, Any]], pred: Callable[[dict[str, Any]], bool], limit: int = 400
) -> dict[str, Any]:
    """Read WebSocket messages until one satisfies ``pred``."""
    for _ in range(limit):
        msg = receive()
        if pred(msg):
            return msg
    raise AssertionError(f"no matching message in {limit} messages")


def wait_status(client: TestClient, state: str, timeout_s: float = 10.0) -> dict[str, Any]:
    """Poll ``/api/status`` until the ride is in ``state``."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        status = client.get("/api/status").json()
        if status["state"] == state:
            return status
        time.sleep(0.02)
    raise AssertionError(f"the ride did not reach {state!r}: {status}")
