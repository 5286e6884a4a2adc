"""The total deadline of remote calls and the STOP lane, against endpoints on 127.0.0.1
that hang or drip one byte a second (the real ``openai`` SDK in between)."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from explaindrive.cli import explain, interpret
from explaindrive.commands import Command
from explaindrive.language.backends.deadline import DeadlineExceededError
from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter, RuleDecider
from explaindrive.language.backends.openai import (
    ChatClient,
    OpenAIDecider,
    OpenAIIntentInterpreter,
)
from explaindrive.language.config import OpenAIConfig
from explaindrive.language.explanation.summary import StateRecord
from tests.language.conftest import MisbehavingEndpoint, ScriptedOpenAI

DEADLINE_S = 0.8
# [s] thread start-up and the embedded fallback on a loaded machine; the endpoints would
# take 25 s (the fast drip) to forever (the hang), so the bound still shows the deadline
SLACK_S = 1.5


def client(url: str, deadline_s: float = DEADLINE_S, retries: int = 0) -> ChatClient:
    return ChatClient(
        OpenAIConfig(base_url=url, api_key="test", timeout_s=deadline_s, max_retries=retries)
    )


def test_a_call_ends_at_its_total_deadline(bad_endpoint: MisbehavingEndpoint) -> None:
    # the drip sends its first byte after 1 s: at 0.8 s per read the SDK's own timeout
    # would never fire, and the whole reply would take minutes
    chat = client(bad_endpoint.base_url)
    t0 = time.monotonic()
    with pytest.raises(DeadlineExceededError, match=r"0\.8 s deadline"):
        chat.complete("system", "user", 0.0)
    assert DEADLINE_S <= time.monotonic() - t0 < DEADLINE_S + SLACK_S
    assert bad_endpoint.requests == 1


def test_retries_stay_within_the_deadline(bad_endpoint: MisbehavingEndpoint) -> None:
    chat = client(bad_endpoint.base_url, retries=3)
    t0 = time.monotonic()
    with pytest.raises(DeadlineExceededError):
        chat.complete("system", "user", 0.0)
    assert time.monotonic() - t0 < DEADLINE_S + SLACK_S


def test_a_drip_faster_than_the_deadline_still_ends_it() -> None:
    # one byte every 0.1 s: every read succeeds, the reply (about 250 bytes) needs 25 s
    srv = MisbehavingEndpoint("drip", interval_s=0.1)
    try:
        chat = client(srv.base_url)
        t0 = time.monotonic()
        with pytest.raises(DeadlineExceededError):
            chat.complete("system", "user", 0.0)
        assert time.monotonic() - t0 < DEADLINE_S + SLACK_S
    finally:
        srv.close()


def test_http_500_is_retried_within_the_deadline(openai_server: ScriptedOpenAI) -> None:
    openai_server.script = [("http", 500), ("ok", "[EXPLAIN]")]
    assert client(openai_server.base_url, retries=1).complete("s", "u", 0.0) == "[EXPLAIN]"
    assert len(openai_server.requests) == 2


def test_stop_is_read_offline_without_asking_the_endpoint(
    bad_endpoint: MisbehavingEndpoint, interpreter: EmbeddedIntentInterpreter
) -> None:
    it = OpenAIIntentInterpreter(client(bad_endpoint.base_url), interpreter)
    r = it.interpret("Stop here please, I'll get out.")
    assert (r.intent, r.stop_lane, r.backend, r.fallback) == (Command.STOP, True, "embedded", False)
    assert r.latency_s < 0.5 and bad_endpoint.requests == 0


def test_other_requests_fall_back_at_the_deadline(
    bad_endpoint: MisbehavingEndpoint, interpreter: EmbeddedIntentInterpreter
) -> None:
    it = OpenAIIntentInterpreter(client(bad_endpoint.base_url), interpreter)
    r = it.interpret("I'm late for my train, could you please hurry?")
    assert (r.intent, r.fallback, r.stop_lane) == (Command.FAST, True, False)
    assert "deadline" in (r.error or "")
    assert DEADLINE_S <= r.latency_s < DEADLINE_S + SLACK_S


def test_decisions_fall_back_at_the_deadline(bad_endpoint: MisbehavingEndpoint) -> None:
    red = StateRecord.model_validate(
        {
            "request": "fast",
            "action": -2,
            "state": {"v_ego": 9.0, "v_lim": 13.9, "d_tl": 30.0, "tl_state": "red"},
        }
    )
    d = OpenAIDecider(client(bad_endpoint.base_url), RuleDecider()).decide(red)
    assert d.fallback and d.explain and d.latency_s < DEADLINE_S + SLACK_S


def test_interpret_cli_returns_within_its_deadline(
    bad_endpoint: MisbehavingEndpoint, interpreter: EmbeddedIntentInterpreter, tmp_path: Path
) -> None:
    config = tmp_path / "lang.yaml"
    config.write_text(
        f"openai: {{base_url: '{bad_endpoint.base_url}', api_key: test, timeout_s: {DEADLINE_S}}}\n"
    )
    app = typer.Typer()
    for module in (interpret, explain):
        module.register(app)
    args = ["interpret", "Please hurry, I'm late", "--backend", "openai", "--config", str(config)]
    res = CliRunner().invoke(app, [*args, "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert (out["intent"], out["fallback"]) == ("fast", True)
    assert DEADLINE_S <= out["latency_s"] < DEADLINE_S + SLACK_S
    assert "deadline" in out["error"]
