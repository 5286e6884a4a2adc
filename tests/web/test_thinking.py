"""Each frame says which language modules are at work and counts their answers."""

from __future__ import annotations

from fastapi.testclient import TestClient

from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.web import create_app

from ..ride.fakes import ScriptedController, fake_language
from .conftest import STEP_PERIOD_S, TEST_HOST, wait_for


def slow_factory(config: RideConfig) -> RideSession:
    return RideSession(config, ScriptedController(), fake_language(delay_s=0.5))


def test_frames_show_the_car_thinking_and_the_counts_per_module() -> None:
    app = create_app(slow_factory, step_period_s=STEP_PERIOD_S, hosts=(TEST_HOST,))
    with TestClient(app) as client, client.websocket_connect("/ws") as ws:
        ws.receive_json()
        client.post("/api/ride/start", json={"traffic_level": 0.5, "seed": 3, "max_steps": 60})
        first = wait_for(ws.receive_json, lambda m: m.get("type") == "frame")
        assert first["thinking"] == [] and set(first["models"]) == {
            "interpret",
            "decide",
            "explain",
        }
        # "slow" makes the fake LLM-1 take 0.5 s: ten steps of 0.05 s see it at work
        client.post("/api/ride/say", json={"text": "hurry, we are slow"})
        busy = wait_for(ws.receive_json, lambda m: "interpret" in m.get("thinking", []))
        assert busy["models"]["interpret"]["used"] == 0
        done = wait_for(
            ws.receive_json, lambda m: m.get("models", {}).get("interpret", {}).get("used") == 1
        )
        assert "interpret" not in done["thinking"]
        client.post("/api/ride/reset")
