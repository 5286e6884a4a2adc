"""Fixtures for the web tests: the app over fake language modules and a scripted driver."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from explaindrive.language.speech import Transcript
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.web import create_app

from ..ride.fakes import ScriptedController, fake_language

STEP_PERIOD_S = 0.05  # [s] twenty control steps per second of wall time


class UploadTranscriber:
    """Stands in for Whisper: a WAV upload 'says' it is in a hurry, anything else is silence."""

    def load(self) -> None:
        pass

    def transcribe(self, path: str | Path) -> Transcript:
        text = "please hurry" if Path(path).read_bytes()[:4] == b"RIFF" else ""
        return Transcript(text, 1.0, 0.0, "en")


def fake_session_factory(config: RideConfig) -> RideSession:
    """A ride over live SUMO with the rule-based driver and keyword language modules."""
    language = replace(fake_language(), transcriber=UploadTranscriber())
    return RideSession(config, ScriptedController(), language)


@pytest.fixture
def client() -> Iterator[TestClient]:
    app = create_app(fake_session_factory, step_period_s=STEP_PERIOD_S, max_upload_bytes=64_000)
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
