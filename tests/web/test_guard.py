"""The checks at the door: Host, Origin, body size, short error answers, no CDN docs."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient
from starlette.testclient import WebSocketDenialResponse

from explaindrive.web import create_app
from explaindrive.web.app import MAX_JSON_BYTES
from explaindrive.web.guard import host_name, served_hosts

from .conftest import STEP_PERIOD_S, TEST_ORIGIN, fake_session_factory, wav

EVIL = "http://evil.example"
START = {"traffic_level": 0.5, "seed": 3, "max_steps": 300}
STATE_CHANGING = [
    ("/api/ride/start", START),
    ("/api/ride/pause", None),
    ("/api/ride/resume", None),
    ("/api/ride/reset", None),
    ("/api/ride/say", {"text": "hurry"}),
    ("/api/ride/answer", {"yes": True}),
]


@pytest.mark.parametrize(
    ("bind", "extra", "names"),
    [
        ("127.0.0.1", (), {"127.0.0.1", "localhost", "::1"}),
        ("::1", (), {"127.0.0.1", "localhost", "::1"}),
        ("0.0.0.0", ("car.local",), {"127.0.0.1", "localhost", "::1", "car.local"}),
        ("192.168.1.20", (), {"192.168.1.20"}),
        ("[fd00::2]", ("Car.Local",), {"fd00::2", "car.local"}),
    ],
)
def test_served_hosts(bind, extra, names):
    assert served_hosts(bind, extra) == names


@pytest.mark.parametrize(
    ("header", "name"),
    [
        ("127.0.0.1:8000", "127.0.0.1"),
        ("LocalHost", "localhost"),
        ("[::1]:8000", "::1"),
        ("[::1", ""),
        ("evil.example:80", "evil.example"),
    ],
)
def test_host_name(header, name):
    assert host_name(header) == name


def test_default_hosts_are_the_loopback_names():
    app = create_app(fake_session_factory, step_period_s=STEP_PERIOD_S)
    with TestClient(app, base_url="http://127.0.0.1:8000") as client:
        for host in ("127.0.0.1:8000", "localhost:8000", "[::1]:8000", "localhost"):
            assert client.get("/api/status", headers={"host": host}).status_code == 200
        for host in ("evil.example", "evil.example:8000", "127.0.0.2:8000", ""):
            res = client.get("/api/status", headers={"host": host})
            assert res.status_code == 400 and "Host" in res.json()["detail"], host


def test_a_rebound_name_reaches_nothing(client):
    """DNS rebinding: a foreign name pointing at 127.0.0.1 gets 400 on every path."""
    for path in ("/", "/api/status", "/api/scene", "/static/app.js"):
        assert client.get(path, headers={"host": "evil.example:8000"}).status_code == 400
    res = client.post("/api/ride/start", json=START, headers={"host": "evil.example"})
    assert res.status_code == 400
    assert client.get("/api/status").json()["state"] == "idle"


@pytest.mark.parametrize(("path", "body"), STATE_CHANGING)
@pytest.mark.parametrize(
    "headers",
    [
        {"origin": EVIL},
        {"origin": "null"},
        {"origin": "http://testserver:8001"},  # another port is another origin
        {"origin": "ftp://testserver"},
        {"origin": TEST_ORIGIN, "sec-fetch-site": "cross-site"},
        {"sec-fetch-site": "same-site"},
    ],
)
def test_cross_origin_posts_are_refused(client, path, body, headers):
    res = (
        client.post(path, json=body, headers=headers)
        if body
        else client.post(path, headers=headers)
    )
    assert res.status_code == 403, res.text
    assert "refused" in res.json()["detail"]
    assert client.get("/api/status").json()["state"] == "idle"  # nothing was started


def test_cross_origin_audio_upload_is_refused(client):
    assert (
        client.post("/api/ride/start", json=START, headers={"origin": TEST_ORIGIN}).status_code
        == 200
    )
    files = {"file": ("a.wav", wav(1.0), "audio/wav")}
    res = client.post("/api/ride/audio", files=files, headers={"origin": EVIL})
    assert res.status_code == 403
    assert client.post("/api/ride/pause", headers={"origin": EVIL}).status_code == 403
    assert client.get("/api/status").json()["state"] == "running"
    res = client.post("/api/ride/audio", files=files, headers={"origin": TEST_ORIGIN})
    assert res.status_code == 202
    client.post("/api/ride/reset")


def test_same_origin_and_originless_posts_pass(client):
    res = client.post(
        "/api/ride/pause", headers={"origin": TEST_ORIGIN, "sec-fetch-site": "same-origin"}
    )
    assert res.status_code == 409  # reached the ride: there is nothing to pause
    assert client.post("/api/ride/pause").status_code == 409  # curl, scripts: no Origin


def test_reads_need_no_origin_check(client):
    assert client.get("/api/status", headers={"origin": EVIL}).status_code == 200


def test_cross_origin_websocket_is_refused(client):
    for headers, status in (({"origin": EVIL}, 403), ({"host": "evil.example"}, 400)):
        with (
            pytest.raises(WebSocketDenialResponse) as denied,
            client.websocket_connect("/ws", headers=headers),
        ):
            pass
        assert denied.value.status_code == status
    with client.websocket_connect("/ws", headers={"origin": TEST_ORIGIN}) as ws:
        assert ws.receive_json()["type"] == "snapshot"
    assert client.app.state.manager.listener_count == 0


def test_a_50_mb_json_body_gets_a_short_answer(client):
    big = b'{"text": "' + b"x" * 50_000_000 + b'"}'
    res = client.post("/api/ride/say", content=big, headers={"content-type": "application/json"})
    assert res.status_code == 413
    assert res.json() == {"detail": f"the request body exceeds {MAX_JSON_BYTES} bytes"}
    assert len(res.content) < 100


def test_a_body_without_length_is_counted_too(client):
    """A generator is sent without Content-Length: the guard counts what arrives (the
    cut-off of a real chunked stream is tested against a live server)."""

    def chunks():
        for _ in range(4):
            yield b"x" * 8192

    res = client.post(
        "/api/ride/say", content=chunks(), headers={"content-type": "application/json"}
    )
    assert "content-length" not in res.request.headers
    assert res.status_code == 413 and len(res.content) < 100


def test_validation_errors_do_not_echo_the_input(client):
    text = "y" * 10_000  # under the body limit, over the field's 300 characters
    res = client.post("/api/ride/say", json={"text": text, "z" * 4000: 1})
    assert res.status_code == 422
    assert "yyyyyyyyyy" not in res.text and len(res.content) < 1000
    fields = {err["loc"][-1][:10] for err in res.json()["detail"]}
    assert fields == {"text", "zzzzzzzzzz"}
    res = client.post(
        "/api/ride/start", content=b"{not json", headers={"content-type": "application/json"}
    )
    assert res.status_code == 422 and res.json()["detail"][0]["type"] == "json_invalid"


def test_no_docs_from_a_cdn(client):
    assert client.get("/docs").status_code == 404
    assert client.get("/redoc").status_code == 404
    schema = client.get("/openapi.json")
    assert schema.status_code == 200 and "/api/ride/say" in schema.json()["paths"]
