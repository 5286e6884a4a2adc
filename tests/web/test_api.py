"""Every endpoint of the web app, with a live SUMO ride over fake language modules."""

from __future__ import annotations

import time

import pytest
from fastapi.testclient import TestClient

from explaindrive.ride.config import RideConfig
from explaindrive.web import RealStack, create_app

from .conftest import (
    STEP_PERIOD_S,
    UploadTranscriber,
    fake_session_factory,
    wait_for,
    wait_status,
    wav,
)
from .flac import flac_bomb

WAV = wav(1.0)
HEADER_ONLY_WAV = b"RIFF\x24\x00\x00\x00WAVEfmt " + bytes(28)
START = {"traffic_level": 0.5, "seed": 3, "max_steps": 300}


def test_page_and_static_files(client):
    page = client.get("/")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    for testid in ("road", "chart", "say-input", "record", "yes", "no", "explanations", "start"):
        assert f'data-testid="{testid}"' in page.text
    assert "http://" not in page.text and "https://" not in page.text  # no CDN: the car is offline
    js = client.get("/static/app.js")
    assert js.status_code == 200 and "new WebSocket" in js.text
    assert client.get("/static/style.css").status_code == 200
    assert client.get("/static/../app.py").status_code == 404
    assert client.get("/static/%2e%2e/app.py").status_code == 404


def test_scene_and_idle_status(client):
    scene = client.get("/api/scene").json()
    assert len(scene["lanes"]) > 50 and len(scene["signals"]) == 8
    status = client.get("/api/status").json()
    assert status["state"] == "idle" and status["settings"] is None
    assert status["question"] is None and status["step_period_s"] == STEP_PERIOD_S


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"traffic_level": 0}, "traffic_level"),
        ({"traffic_level": -1}, "traffic_level"),
        ({"traffic_level": 9}, "traffic_level"),
        ({"traffic_level": "lots"}, "traffic_level"),
        ({"seed": -1}, "seed"),
        ({"seed": 2**31}, "seed"),
        ({"seed": 1.5}, "seed"),
        ({"command": "fly"}, "command"),
        ({"max_steps": 0}, "max_steps"),
        ({"max_steps": 100_000}, "max_steps"),
        ({"traffic": 1.0}, "traffic"),  # unknown field: a typo is an error, not a default
    ],
)
def test_start_rejects_bad_settings(client, body, field):
    res = client.post("/api/ride/start", json=body)
    assert res.status_code == 422
    assert field in {str(part) for err in res.json()["detail"] for part in err["loc"]}
    assert client.get("/api/status").json()["state"] == "idle"


def test_start_needs_json(client):
    assert client.post("/api/ride/start", content=b"seed=3").status_code == 422


@pytest.mark.parametrize(
    ("path", "body"),
    [
        ("/api/ride/pause", None),
        ("/api/ride/resume", None),
        ("/api/ride/say", {"text": "hurry"}),
        ("/api/ride/answer", {"yes": True}),
    ],
)
def test_commands_need_a_ride(client, path, body):
    res = client.post(path, json=body) if body else client.post(path)
    assert res.status_code == 409
    assert "ride" in res.json()["detail"]


def test_audio_needs_a_ride(client):
    res = client.post("/api/ride/audio", files={"file": ("a.wav", WAV, "audio/wav")})
    assert res.status_code == 409


@pytest.mark.parametrize(
    "body",
    [{"text": ""}, {"text": "   "}, {"text": "x" * 301}, {"text": 5}, {}, {"text": "hi", "x": 1}],
)
def test_say_rejects_bad_text(client, body):
    assert client.post("/api/ride/say", json=body).status_code == 422


@pytest.mark.parametrize("body", [{}, {"yes": "maybe"}, {"yes": True, "why": "x"}])
def test_answer_rejects_bad_body(client, body):
    assert client.post("/api/ride/answer", json=body).status_code == 422


def test_a_ride_through_the_api(client):
    """Start, watch, ask, confirm, pause, resume, upload audio, reset."""
    manager = client.app.state.manager
    with client.websocket_connect("/ws") as ws:
        first = ws.receive_json()
        assert first["type"] == "snapshot" and first["status"]["state"] == "idle"
        res = client.post("/api/ride/start", json=START)
        assert res.status_code == 200
        assert res.json()["state"] == "running" and res.json()["settings"]["command"] == "comfort"
        assert client.post("/api/ride/start", json=START).status_code == 409

        frame = wait_for(ws.receive_json, lambda m: m["type"] == "frame")
        assert frame["command"] == "comfort" and frame["ride"] == 1
        assert set(frame["state"]) >= {"v_ego", "v_lim", "d_tl", "tls"}
        ego = frame["scene"]["ego"]
        assert ego["id"] == "ego" and 0 <= ego["x"] <= 1550 and ego["length"] > 0
        assert all(
            s["colour"] in {"red", "yellow", "green", "off"} for s in frame["scene"]["signals"]
        )

        assert client.post("/api/ride/answer", json={"yes": True}).status_code == 409  # no question
        res = client.post("/api/ride/say", json={"text": "  I'm in a hurry  "})
        assert res.status_code == 202 and res.json() == {"id": 1}
        asked = wait_for(ws.receive_json, lambda m: m["type"] == "frame" and m["question"])
        assert asked["question"] == "You want me to drive faster, is this correct?"
        line = next(e for e in asked["passenger"] if e["type"] == "line")
        assert line["text"] == "I'm in a hurry"  # stripped
        assert client.get("/api/status").json()["question"] == asked["question"]
        t_confirm = asked["t"]
        res = client.post("/api/ride/answer", json={"yes": True})
        assert res.status_code == 200 and res.json() == {"id": 1, "answer": "yes"}
        fast = wait_for(ws.receive_json, lambda m: m["type"] == "frame" and m["command"] == "fast")
        confirmed = next(
            e for e in fast["passenger"] if e["type"] == "confirmed" and e["to"] == "fast"
        )
        # applied at the step that took the answer (the ride runs on while the test waits)
        assert t_confirm <= confirmed["t"] <= fast["t"] <= confirmed["t"] + 1

        assert client.post("/api/ride/resume").status_code == 409
        assert client.post("/api/ride/pause").json()["state"] == "paused"
        assert client.post("/api/ride/pause").status_code == 409
        wait_for(ws.receive_json, lambda m: m["type"] == "status" and m["state"] == "paused")
        t_paused = client.get("/api/status").json()["t"]
        time.sleep(10 * STEP_PERIOD_S)
        assert client.get("/api/status").json()["t"] == t_paused  # no steps while paused
        assert client.post("/api/ride/resume").json()["state"] == "running"

        # a late-joining page starts from the history so far
        with client.websocket_connect("/ws") as late:
            snap = late.receive_json()
            assert snap["type"] == "snapshot" and snap["status"]["state"] == "running"
            assert len(snap["history"]) >= t_paused
            assert [h["t"] for h in snap["history"]] == sorted({h["t"] for h in snap["history"]})
            assert any(e["type"] == "confirmed" for e in snap["log"])
            nxt = wait_for(late.receive_json, lambda m: m["type"] == "frame")
            assert nxt["t"] > snap["history"][-1]["t"] - 1
        assert manager.listener_count == 1

        # a spoken line: decoded, stored under a server-chosen name, transcribed, deleted
        res = client.post("/api/ride/audio", files={"file": ("../../etc/passwd", WAV, "audio/wav")})
        assert res.status_code == 202 and res.json() == {"id": 2}
        heard = wait_for(
            ws.receive_json,
            lambda m: (
                m["type"] == "frame" and any(e["type"] == "transcript" for e in m["passenger"])
            ),
        )
        transcript = next(e for e in heard["passenger"] if e["type"] == "transcript")
        assert transcript["text"] == "please hurry"
        ((name, size, duration_s),) = UploadTranscriber.seen
        assert name.startswith("utterance-") and name.endswith(".wav") and "passwd" not in name
        assert (size, duration_s) == (44 + 2 * 16_000, 1.0)  # 1 s of 16 kHz 16-bit mono
        assert list(manager.upload_dir.iterdir()) == []  # deleted once transcribed
        spoken = [e for m in [heard] for e in m["passenger"] if e["type"] == "line"]
        assert all(e["audio"] in (None, "uploaded recording") for e in spoken)  # no server paths
        wait_for(ws.receive_json, lambda m: m["type"] == "frame" and m["question"])
        assert client.post("/api/ride/answer", json={"yes": False}).json()["answer"] == "no"
        kept = wait_for(
            ws.receive_json,
            lambda m: (
                m["type"] == "frame" and any(e["type"] == "cancelled" for e in m["passenger"])
            ),
        )
        assert kept["command"] == "fast"

        res = client.post("/api/ride/reset")
        assert res.status_code == 200 and res.json()["state"] == "idle"
        wait_for(ws.receive_json, lambda m: m["type"] == "status" and m["state"] == "idle")
        assert client.post("/api/ride/say", json={"text": "hurry"}).status_code == 409


@pytest.mark.parametrize(
    ("files", "status", "words"),
    [
        ({"file": ("a.txt", b"hello", "text/plain")}, 415, "unsupported content type"),
        ({"file": ("a.wav", b"OggS" + bytes(40), "audio/wav")}, 415, "a ogg file"),
        ({"file": ("a.wav", b"", "audio/wav")}, 422, "empty"),
        ({"file": ("a.wav", WAV + bytes(40_000), "audio/wav")}, 413, "upload exceeds 64000 bytes"),
        ({"file": ("a.wav", WAV + bytes(60_000), "audio/wav")}, 413, "body exceeds 80384 bytes"),
        ({"file": ("a.wav", HEADER_ONLY_WAV, "audio/wav")}, 415, "cannot be decoded"),
        ({"file": ("a.flac", flac_bomb(60), "audio/flac")}, 413, "longer than 30 s"),
        ({"file": ("a.wav", wav(31.0, rate_hz=1000), "audio/wav")}, 413, "longer than 30 s"),
        ({"audio": ("a.wav", WAV, "audio/wav")}, 422, "multipart field 'file'"),
        ([("file", ("a.wav", WAV, "audio/wav"))] * 2, 400, "unreadable upload"),
        (None, 422, "multipart field 'file'"),
    ],
)
def test_audio_rejects_bad_uploads(client, files, status, words):
    assert client.post("/api/ride/start", json={**START, "max_steps": 100}).status_code == 200
    if files is None:
        res = client.post("/api/ride/audio", data={}, files={})
    else:
        res = client.post("/api/ride/audio", files=files)
    assert res.status_code == status, res.text
    assert words in res.json()["detail"]
    assert list(client.app.state.manager.upload_dir.iterdir()) == []
    client.post("/api/ride/reset")


def test_two_pages_see_the_same_frames(client):
    with client.websocket_connect("/ws") as a, client.websocket_connect("/ws") as b:
        a.receive_json(), b.receive_json()
        client.post("/api/ride/start", json={**START, "max_steps": 8})
        first_a = wait_for(a.receive_json, lambda m: m["type"] == "frame")
        first_b = wait_for(b.receive_json, lambda m: m["type"] == "frame")
        assert first_a == first_b
        seen_a = wait_for(
            a.receive_json, lambda m: m["type"] == "status" and m["state"] == "finished"
        )
        seen_b = wait_for(
            b.receive_json, lambda m: m["type"] == "status" and m["state"] == "finished"
        )
        assert seen_a["t"] == seen_b["t"] == 8.0
    status = wait_status(client, "finished")
    assert status["settings"]["max_steps"] == 8
    res = client.post("/api/ride/start", json={**START, "max_steps": 3})  # a finished ride restarts
    assert res.status_code == 200 and res.json()["ride"] == 2
    wait_status(client, "finished")


def test_a_ride_that_cannot_start():
    calls = []

    def broken(config: RideConfig):
        calls.append(config)
        if len(calls) == 1:
            raise FileNotFoundError("policy fast.pt not found")
        return fake_session_factory(config)

    app = create_app(broken, step_period_s=STEP_PERIOD_S)  # answers the loopback names
    with TestClient(app, base_url="http://127.0.0.1:8000") as client:
        res = client.post("/api/ride/start", json=START)
        assert res.status_code == 503 and "policy fast.pt not found" in res.json()["detail"]
        status = client.get("/api/status").json()
        assert status["state"] == "failed" and "FileNotFoundError" in status["error"]
        res = client.post("/api/ride/start", json={**START, "max_steps": 3})
        assert res.status_code == 200
        assert calls[1].realtime and calls[1].traffic_level == 0.5 and calls[1].seed == 3
        client.post("/api/ride/reset")


def test_real_stack_checks_the_backend() -> None:
    with pytest.raises(ValueError, match="unknown language backend"):
        RealStack("gpt9")
    assert RealStack("openai").backend == "openai"  # models load on the first ride
