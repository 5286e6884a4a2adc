"""A STOP is never lost to a slow model: real-time rides with the ``openai`` backend
against endpoints on 127.0.0.1 that hang or drip one byte a second (shipped policies,
live SUMO, the embedded MiniLM model reading every line first)."""

from __future__ import annotations

from pathlib import Path

import pytest

from explaindrive.agent.controller import MergedController
from explaindrive.env.metrics import stop_latency_bound
from explaindrive.language.config import LanguageConfig, OpenAIConfig
from explaindrive.language.stack import make_language_stack
from explaindrive.ride.config import RideConfig
from explaindrive.ride.runner import run_ride
from explaindrive.ride.script import ScriptLine
from explaindrive.ride.session import RideSession
from tests.language.conftest import MisbehavingEndpoint

STOP_AT_S = 8


@pytest.mark.parametrize("mode", ["hang", "drip"])
def test_a_real_time_ride_stops_although_the_endpoint_never_answers(
    mode: str, tmp_path: Path
) -> None:
    endpoint = MisbehavingEndpoint(mode)
    try:
        config = LanguageConfig(openai=OpenAIConfig(base_url=endpoint.base_url, api_key="test"))
        language = make_language_stack("openai", config).load()
        session = RideSession(
            RideConfig(max_steps=STOP_AT_S + 12, backend="openai", realtime=True, seed=1),
            MergedController.from_package(),
            language,
        )
        script = [
            ScriptLine(t=0, say="I'm late for a meeting, could you please hurry?", confirm="yes"),
            ScriptLine(t=STOP_AT_S, say="Stop here please, I'll get out.", confirm="yes"),
        ]
        run_ride(session, script, tmp_path)
    finally:
        endpoint.close()
    events = [e for r in session.records for e in r.passenger]
    read = [e for e in events if e["type"] == "interpretation"]
    # the hurry goes to the endpoint and falls back at the model's deadline
    # (openai.timeout_s), inside the ride's budget for the line (interpret_deadline_s):
    # the fallback, not the lane's late path, answers it
    assert (read[0]["intent"], read[0]["fallback"]) == ("fast", True)
    assert "deadline" in read[0]["error"]
    budget = (OpenAIConfig().timeout_s, RideConfig().interpret_deadline_s)
    assert budget[0] <= read[0]["latency_s"] < budget[1], (read[0]["latency_s"], budget)
    # the STOP is read offline at once, the endpoint is never asked
    stop = read[1]
    assert (stop["intent"], stop["stop_lane"], stop["backend"]) == ("stop", True, "embedded")
    assert stop["latency_s"] < 0.5
    said = endpoint.said()
    assert "I'm late for a meeting, could you please hurry?" in said
    assert not any("Stop here" in text for text in said)
    recs = session.records
    confirmed = [e for e in events if e["type"] == "confirmed"]
    assert [e["to"] for e in confirmed] == ["fast", "stop"]
    assert not [e for e in events if e["type"] == "late" and e["module"] == "interpret"]
    stop_step = int(confirmed[1]["t"])  # confirmed when this step collected it
    # said before step 8, read in tens of milliseconds, so collected by step 9 at the latest
    assert STOP_AT_S <= stop_step <= STOP_AT_S + 1
    assert recs[stop_step].command == "stop" and recs[stop_step - 1].command == "fast"
    speed = recs[stop_step - 1].speed_mps
    standstill = next(i for i in range(stop_step, len(recs)) if recs[i].speed_mps == 0.0)
    assert standstill - stop_step + 1 <= stop_latency_bound(speed), (speed, standstill)
    assert speed > 3.0  # the car was moving when the passenger asked
    decided = [r.decision for r in recs if r.decision and "backend" in r.decision]
    assert decided and all(d["fallback"] for d in decided)  # LLM-2 fell back every time
