"""Secrets from a remote endpoint never reach a log, an event file or a page."""

from __future__ import annotations

import json
import logging
import threading
from collections.abc import Iterator
from dataclasses import replace
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest

from explaindrive.language.backends.embedded import RuleDecider
from explaindrive.language.backends.openai import ChatClient, OpenAIDecider
from explaindrive.language.config import OpenAIConfig
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.interpreter import IntentResult
from explaindrive.redact import MASK, RedactingFilter, redact, redact_json
from explaindrive.ride.config import RideConfig
from explaindrive.ride.runner import run_ride
from explaindrive.ride.script import ScriptLine
from explaindrive.ride.session import RideSession

from .ride.fakes import KeywordInterpreter, ScriptedController, fake_language

KEY = "sk-proj-Zq81TestKey0123456789abcdef"
RED = StateRecord.model_validate(
    {
        "request": "fast",
        "action": -2,
        "state": {"v_ego": 9.0, "v_lim": 13.9, "d_tl": 30.0, "tl_state": "red"},
    }
)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (f"Incorrect API key provided: {KEY}.", f"Incorrect API key provided: {MASK}."),
        ("Authorization: Bearer abc.DEF-123_x/y+z==", f"Authorization: Bearer {MASK}"),
        ('{"api_key": "hunter2-not-an-sk"}', f'{{"api_key": "{MASK}"}}'),
        ("?access_token=eyJhbGciOi&x=1", f"?access_token={MASK}&x=1"),
        ("password=correct horse", f"password={MASK} horse"),
        ("the ego brakes for the red light at 30 m", "the ego brakes for the red light at 30 m"),
        ("task-list and desk-lamp", "task-list and desk-lamp"),  # "sk-" inside words stays
    ],
)
def test_patterns(text: str, expected: str) -> None:
    assert redact(text) == expected


def test_named_and_environment_secrets(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("OPENAI_API_KEY", "local-server-token-42")
    text = "echo: local-server-token-42 / my-own-key-999 / test"
    assert redact(text, ["my-own-key-999", "test", None]) == f"echo: {MASK} / {MASK} / test"
    nested = {"a": [text, 3, {"b": ("x", KEY)}], "n": None}
    assert redact_json(nested) == {
        "a": [f"echo: {MASK} / my-own-key-999 / test", 3, {"b": ["x", MASK]}],
        "n": None,
    }


def test_log_filter_masks_messages_and_tracebacks() -> None:
    record = logging.LogRecord("x", logging.WARNING, __file__, 1, "failed: %s", (KEY,), None)
    try:
        raise RuntimeError(f"Bearer {KEY}")
    except RuntimeError:
        import sys

        record.exc_info = sys.exc_info()
    assert RedactingFilter().filter(record)
    formatted = logging.Formatter().format(record)
    assert KEY not in formatted and formatted.startswith(f"failed: {MASK}")
    assert f"RuntimeError: Bearer {MASK}" in formatted


class EchoingEndpoint:
    """An OpenAI-compatible endpoint on 127.0.0.1 that answers 401, echoing the key it got."""

    def __init__(self) -> None:
        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: Any) -> None:
                pass

            def do_POST(self) -> None:
                self.rfile.read(int(self.headers.get("Content-Length", "0")))
                got = self.headers.get("Authorization", "")
                message = f"Incorrect API key provided: {got.split()[-1]}. Header was: {got}"
                body = json.dumps({"error": {"message": message}}).encode()
                self.send_response(401)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.base_url = f"http://127.0.0.1:{self.server.server_address[1]}/v1"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def endpoint() -> Iterator[EchoingEndpoint]:
    srv = EchoingEndpoint()
    yield srv
    srv.close()


def test_openai_errors_that_echo_the_key_are_masked(
    endpoint: EchoingEndpoint, caplog: pytest.LogCaptureFixture
) -> None:
    client = ChatClient(OpenAIConfig(base_url=endpoint.base_url, api_key=KEY, timeout_s=5.0))
    with caplog.at_level(logging.WARNING):
        decision = OpenAIDecider(client, RuleDecider()).decide(RED)
    assert decision.fallback and "401" in (decision.error or "")
    assert KEY not in (decision.error or "") and MASK in (decision.error or "")
    assert caplog.records and all(KEY not in r.getMessage() for r in caplog.records)


class LeakyInterpreter(KeywordInterpreter):
    """Answers like a fallback whose error text holds the key."""

    def interpret(self, text: str) -> IntentResult:
        result = super().interpret(text)
        return replace(result, fallback=True, error=f"AuthenticationError: bad key {KEY}")


def test_ride_events_never_hold_the_key(tmp_path: Path) -> None:
    language = replace(fake_language(), interpreter=LeakyInterpreter())
    config = RideConfig(traffic_level=0.5, seed=3, max_steps=8)
    session = RideSession(config, ScriptedController(), language)
    run_ride(session, [ScriptLine(t=0, say="please hurry", confirm="yes")], tmp_path)
    events = (tmp_path / "events.jsonl").read_text()
    assert KEY not in events and f"bad key {MASK}" in events
    assert KEY not in (tmp_path / "summary.json").read_text()
