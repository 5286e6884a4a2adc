"""``explaindrive ride --config FILE --model NAME`` rides with that endpoint and model."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

from explaindrive.cli.app import app
from tests.language.conftest import ScriptedOpenAI

runner = CliRunner()


@pytest.fixture()
def openai_server() -> Iterator[ScriptedOpenAI]:
    srv = ScriptedOpenAI()
    yield srv
    srv.close()


def test_ride_reaches_the_endpoint_with_the_chosen_model(
    openai_server: ScriptedOpenAI, tmp_path: Path
) -> None:
    config = tmp_path / "local.yaml"
    config.write_text(
        f"backend: openai\nopenai: {{base_url: {openai_server.base_url}, model: from-file}}\n"
    )
    script = tmp_path / "ride.yaml"
    script.write_text('- t: 0\n  say: "I feel a little car sick."\n  confirm: yes\n')
    raw = "Sure! ```You want me to drive more carefully, is this correct?```"
    openai_server.script = [("ok", raw), ("ok", "[NO EXPLANATION NEEDED]")]
    out = tmp_path / "ride"
    args = ["ride", "--config", str(config), "--model", "smollm2", "--script", str(script)]
    res = runner.invoke(app, [*args, "--max-steps", "4", "--no-live", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert openai_server.requests and {b["model"] for b in openai_server.requests} == {"smollm2"}
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    (reading,) = [e for r in events for e in r["passenger"] if e["type"] == "interpretation"]
    assert (reading["intent"], reading["backend"]) == ("comfort", "openai")
    assert reading["raw_reply"] == raw
    assert raw not in res.output  # the log keeps it, the screen does not show it


def test_ride_help_shows_a_local_server_example() -> None:
    res = runner.invoke(app, ["ride", "--help"])
    text = " ".join(res.output.split())  # the help is wrapped to the terminal's width
    assert res.exit_code == 0 and "--model" in text
    assert "'openai: {base_url: http://127.0.0.1:8080/v1, model: smollm2, timeout_s: 3}'" in text
