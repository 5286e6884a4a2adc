"""Uploaded recordings are deleted as soon as they are transcribed or rejected."""

from __future__ import annotations

import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from explaindrive.language.speech.transcriber import AudioError, Transcript
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.web import create_app
from explaindrive.web.manager import MAX_WAITING_UPLOADS
from explaindrive.web.uploads import DeleteAfterUse, UploadTracker

from ..ride.fakes import ScriptedController, fake_language
from .conftest import STEP_PERIOD_S, TEST_HOST, UploadTranscriber, wait_status, wav

START = {"traffic_level": 0.5, "seed": 3, "max_steps": 600}


class Failing:
    def load(self) -> None:
        pass

    def transcribe(self, path: str | Path) -> Transcript:
        raise AudioError("silent")


def test_delete_after_use_deletes_only_its_own_files(tmp_path: Path) -> None:
    uploads, elsewhere = tmp_path / "uploads", tmp_path / "mine"
    uploads.mkdir(), elsewhere.mkdir()
    a, b, c = uploads / "a.wav", uploads / "b.wav", elsewhere / "c.wav"
    for path in (a, b, c):
        path.write_bytes(wav(0.5))
    DeleteAfterUse(UploadTranscriber(), uploads).transcribe(a)
    with pytest.raises(AudioError):
        DeleteAfterUse(Failing(), uploads).transcribe(b)
    DeleteAfterUse(UploadTranscriber(), uploads).transcribe(c)
    assert (a.exists(), b.exists(), c.exists()) == (False, False, True)


def test_tracker_sweeps_files_past_their_deadline(tmp_path: Path) -> None:
    tracker = UploadTracker(max_age_s=0.2)
    old, new = tmp_path / "old.wav", tmp_path / "new.wav"
    old.write_bytes(b"x")
    tracker.add(old)
    time.sleep(0.3)
    new.write_bytes(b"x")
    tracker.add(new)
    assert tracker.waiting() == 2
    assert tracker.sweep() == 1 and not old.exists() and new.exists()
    tracker.clear()
    assert not new.exists() and tracker.waiting() == 0


def test_uploads_of_a_paused_ride_are_deleted_once_transcribed(client: TestClient) -> None:
    manager = client.app.state.manager
    assert client.post("/api/ride/start", json=START).status_code == 200
    assert client.post("/api/ride/pause").status_code == 200
    for _ in range(3):
        res = client.post("/api/ride/audio", files={"file": ("a.wav", wav(1.0), "audio/wav")})
        assert res.status_code == 202
    end = time.monotonic() + 10
    while (len(UploadTranscriber.seen) < 3 or any(manager.upload_dir.iterdir())) and (
        time.monotonic() < end
    ):
        time.sleep(0.02)
    assert [seen[1:] for seen in UploadTranscriber.seen] == [(32_044, 1.0)] * 3
    assert list(manager.upload_dir.iterdir()) == []
    assert client.get("/api/status").json()["state"] == "paused"
    client.post("/api/ride/reset")


def test_rejected_uploads_leave_nothing(client: TestClient) -> None:
    manager = client.app.state.manager
    assert client.post("/api/ride/start", json=START).status_code == 200
    res = client.post(
        "/api/ride/audio", files={"file": ("a.wav", b"RIFF" + bytes(60), "audio/wav")}
    )
    assert res.status_code == 415
    assert list(manager.upload_dir.iterdir()) == []
    client.post("/api/ride/reset")


def test_too_many_waiting_recordings_are_refused() -> None:
    release = threading.Event()

    class Blocking(UploadTranscriber):
        def transcribe(self, path: str | Path) -> Transcript:
            release.wait(10)
            return super().transcribe(path)

    def factory(config: RideConfig) -> RideSession:
        language = replace(fake_language(), transcriber=Blocking())
        return RideSession(config, ScriptedController(), language)

    app = create_app(factory, step_period_s=STEP_PERIOD_S, hosts=(TEST_HOST,))
    with TestClient(app) as client:
        manager = client.app.state.manager
        assert client.post("/api/ride/start", json=START).status_code == 200
        client.post("/api/ride/pause")
        files = {"file": ("a.wav", wav(0.5), "audio/wav")}
        codes = [client.post("/api/ride/audio", files=files).status_code for _ in range(5)]
        assert codes == [202] * MAX_WAITING_UPLOADS + [429]
        assert len(list(manager.upload_dir.iterdir())) == MAX_WAITING_UPLOADS
        release.set()
        end = time.monotonic() + 10
        while list(manager.upload_dir.iterdir()) and time.monotonic() < end:
            time.sleep(0.02)
        assert list(manager.upload_dir.iterdir()) == []
        assert client.post("/api/ride/audio", files=files).status_code == 202
        client.post("/api/ride/reset")
        wait_status(client, "idle")
