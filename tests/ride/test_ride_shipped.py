"""Rides with the shipped policies and the real language layer (embedded, Whisper, openai)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from explaindrive.agent.controller import MergedController
from explaindrive.env.metrics import stop_latency_bound
from explaindrive.language.config import LanguageConfig, OpenAIConfig
from explaindrive.language.stack import LanguageStack, make_language_stack
from explaindrive.ride.config import RideConfig
from explaindrive.ride.runner import run_ride
from explaindrive.ride.script import ScriptLine, default_script_path, load_script
from explaindrive.ride.session import RideSession

from ..language.conftest import ScriptedOpenAI


@pytest.fixture(scope="module")
def language() -> LanguageStack:
    return make_language_stack("embedded").load(speech=True)


def passenger_events(session: RideSession, kind: str) -> list[dict]:
    return [e for r in session.records for e in r.passenger if e["type"] == kind]


def test_default_ride_fast_stop_comfort(language: LanguageStack, tmp_path: Path) -> None:
    # With the shipped networks seed 3 meets a red light while the passenger wants to go fast.
    session = RideSession(RideConfig(seed=3), MergedController.from_package(), language)
    out = run_ride(session, load_script(default_script_path()), tmp_path)
    recs = session.records
    assert [e["to"] for e in passenger_events(session, "confirmed")] == ["fast", "stop", "comfort"]
    stop_start = next(i for i, r in enumerate(recs) if r.command == "stop")
    speed_at_stop = recs[stop_start - 1].speed_mps
    standstill = next(i for i in range(stop_start, len(recs)) if recs[i].speed_mps == 0.0)
    assert standstill - stop_start + 1 <= stop_latency_bound(speed_at_stop)
    comfort = [r for r in recs if r.command == "comfort"]
    assert comfort and max(r.speed_mps for r in comfort) > 0.0  # it drives on
    explained = [r for r in recs if r.explanation and r.command == "fast"]
    assert any(r.explanation["factor"] in ("traffic_light", "pedestrian") for r in explained), [
        r.explanation for r in explained
    ]
    summary = json.loads(out.summary.read_text())
    assert summary["metrics"]["collisions"] == 0
    assert summary["counts"]["explanations"] >= 1
    assert len(out.events.read_text().splitlines()) == len(recs)


@pytest.mark.skipif(shutil.which("espeak-ng") is None, reason="espeak-ng is not installed")
def test_spoken_lines_go_through_whisper(language: LanguageStack, tmp_path: Path) -> None:
    def speak(text: str, name: str) -> Path:
        path = tmp_path / f"{name}.wav"
        subprocess.run(["espeak-ng", "-s", "140", "-w", str(path), text], check=True)
        return path

    silent = tmp_path / "silent.wav"
    silent.write_bytes(b"RIFF\x00\x00\x00\x00WAVEfmt ")  # a truncated, unusable file
    lines = [
        ScriptLine(
            t=0, audio=speak("Please hurry up, I am late for my flight.", "hurry"), confirm="yes"
        ),
        ScriptLine(t=20, audio=silent),
        # (espeak's "Stop the car right now." reaches Whisper tiny.en as "Stop looking alright
        # now.", which LLM-1 reads as an unsure fast: docs/language.md)
        ScriptLine(t=30, audio=speak("Pull over right now.", "stop"), confirm="yes"),
    ]
    session = RideSession(
        RideConfig(max_steps=45, seed=1), MergedController.from_package(), language
    )
    run_ride(session, lines, tmp_path / "out")
    transcripts = passenger_events(session, "transcript")
    assert "hurry" in transcripts[0]["text"].lower()
    assert [e["to"] for e in passenger_events(session, "confirmed")] == ["fast", "stop"]
    (rephrase,) = passenger_events(session, "rephrase")
    assert rephrase["reason"]  # why the audio was unusable
    assert session.records[-1].command == "stop"


def test_openai_backend_that_times_out_falls_back(tmp_path: Path) -> None:
    """Against a scripted OpenAI-compatible server on 127.0.0.1 that answers too late."""
    server = ScriptedOpenAI()
    server.script = [("slow", 2.0, "You want me to drive faster, is this correct?")]
    try:
        config = LanguageConfig(
            openai=OpenAIConfig(base_url=server.base_url, api_key="test", timeout_s=0.3)
        )
        language = make_language_stack("openai", config).load()
        session = RideSession(
            RideConfig(max_steps=12, backend="openai"), MergedController.from_package(), language
        )
        run_ride(session, [ScriptLine(t=0, say="I'm late, hurry please", confirm="yes")], tmp_path)
    finally:
        server.close()
    (interp,) = passenger_events(session, "interpretation")
    assert interp["fallback"] is True and interp["intent"] == "fast"
    assert session.records[-1].command == "fast"
    assert session.counts.fallbacks >= 1
    assert len(session.records) == 12
