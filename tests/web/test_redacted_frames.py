"""Frames sent to every page carry no secret from a remote endpoint's error text."""

from __future__ import annotations

import json
from dataclasses import replace

from fastapi.testclient import TestClient

from explaindrive.redact import MASK
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.web import create_app

from ..ride.fakes import ScriptedController, fake_language
from ..test_redact import KEY, LeakyInterpreter
from .conftest import STEP_PERIOD_S, TEST_HOST, wait_for


def leaky_factory(config: RideConfig) -> RideSession:
    language = replace(fake_language(), interpreter=LeakyInterpreter())
    return RideSession(config, ScriptedController(), language)


def test_frames_mask_the_key() -> None:
    app = create_app(leaky_factory, step_period_s=STEP_PERIOD_S, hosts=(TEST_HOST,))
    with TestClient(app) as client, client.websocket_connect("/ws") as ws:
        ws.receive_json()
        client.post("/api/ride/start", json={"traffic_level": 0.5, "seed": 3, "max_steps": 60})
        client.post("/api/ride/say", json={"text": "please hurry"})
        frame = wait_for(
            ws.receive_json,
            lambda m: any(e["type"] == "interpretation" for e in m.get("passenger", [])),
        )
        (event,) = [e for e in frame["passenger"] if e["type"] == "interpretation"]
        assert event["error"] == f"AuthenticationError: bad key {MASK}"
        with client.websocket_connect("/ws") as late:
            assert KEY not in json.dumps(late.receive_json())  # the snapshot's log too
        client.post("/api/ride/reset")
