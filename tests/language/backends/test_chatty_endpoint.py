"""The ``openai`` backend against a scripted server that answers like real models do:
chatty, wrapped, paraphrased, over-eager or wrong. Every well-formed meaning is used, no
raw markup reaches the passenger, and the state has the last word."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from typer.testing import CliRunner

from explaindrive.cli.app import app
from explaindrive.commands import Command
from explaindrive.language.backends.embedded import (
    EmbeddedIntentInterpreter,
    RuleDecider,
    TemplateExplainer,
)
from explaindrive.language.backends.openai import (
    ChatClient,
    OpenAIDecider,
    OpenAIExplainer,
    OpenAIIntentInterpreter,
)
from explaindrive.language.config import OpenAIConfig
from explaindrive.language.data import DECISIONS_JSONL, data_path
from explaindrive.language.explanation.datasets import load_decisions
from explaindrive.language.explanation.decision import Factor
from explaindrive.language.explanation.grounding import reply_problems
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.interpreter import REPHRASE_MESSAGE, format_confirmation
from tests.language.backends.test_replies import CHATTY_COMFORT

if TYPE_CHECKING:
    from tests.language.conftest import ScriptedOpenAI

runner = CliRunner()
TEMPLATES = {format_confirmation(c) for c in Command} | {REPHRASE_MESSAGE}
SICK = "Could you drive more gently, I feel sick"  # the embedded reading: comfort
RED = StateRecord.model_validate(
    {
        "request": "fast",
        "action": -2,
        "state": {"v_ego": 9.0, "v_lim": 13.9, "d_tl": 30.0, "tl_state": "red"},
    }
)
# a fast request slowed on an empty road: a conflict, but nothing to name
EMPTY = StateRecord.model_validate(
    {"request": "fast", "action": -1, "state": {"v_ego": 6.0, "v_lim": 13.9}}
)


def client(server: ScriptedOpenAI, model: str = "gpt-4.1-mini") -> ChatClient:
    return ChatClient(OpenAIConfig(base_url=server.base_url, api_key="t", model=model))


@pytest.mark.parametrize("reply", CHATTY_COMFORT)
def test_chatty_confirmations_are_accepted(
    openai_server: ScriptedOpenAI, interpreter: EmbeddedIntentInterpreter, reply: str
) -> None:
    openai_server.script = [("ok", reply)]
    r = OpenAIIntentInterpreter(client(openai_server), interpreter).interpret(SICK)
    assert (r.intent, r.backend, r.fallback, r.rule) == (Command.COMFORT, "openai", False, "agree")
    assert r.confirmation == "You want me to drive more carefully, is this correct?"
    assert r.raw_reply == reply


@pytest.mark.parametrize(
    "reply",
    [
        "You want me to drive faster or stop, is this correct?",
        "```\nDrive faster.\nYou want me to drive more carefully, is this correct?\n```",
        "<think>stop?</think>",
        "**Sure!** \U0001f697",
    ],
)
def test_ambiguous_replies_fall_back_and_show_no_markup(
    openai_server: ScriptedOpenAI, interpreter: EmbeddedIntentInterpreter, reply: str
) -> None:
    openai_server.script = [("ok", reply)]
    r = OpenAIIntentInterpreter(client(openai_server), interpreter).interpret(SICK)
    assert (r.intent, r.backend, r.fallback) == (Command.COMFORT, "embedded", True)
    assert r.confirmation in TEMPLATES and "reply not read" in (r.error or "")
    assert r.raw_reply == reply


def test_off_topic_answer_and_a_sure_none(
    openai_server: ScriptedOpenAI, interpreter: EmbeddedIntentInterpreter
) -> None:
    it = OpenAIIntentInterpreter(client(openai_server), interpreter)
    openai_server.script = [("ok", "NOT A DRIVING REQUEST")]
    r = it.interpret("What's the capital of France?")
    assert (r.intent, r.confirmation, r.fallback) == (None, REPHRASE_MESSAGE, False)
    # a well-formed wrong answer does not turn a sure off-topic reading into a command
    openai_server.script = [("ok", "You want me to drive faster, is this correct?")]
    r = it.interpret("What's the capital of France?")
    assert (r.intent, r.rule, r.overruled) == (None, "local-sure-none", True)


def test_a_remote_stop_wins_over_an_unsure_reading_only(
    openai_server: ScriptedOpenAI, interpreter: EmbeddedIntentInterpreter
) -> None:
    it = OpenAIIntentInterpreter(client(openai_server), interpreter)
    openai_server.script = [("ok", "Sure. Shall I pull over here?")]
    unsure = "Around here somewhere."  # embedded: STOP at 0.64, under its threshold: no command
    r = it.interpret(unsure)
    assert (r.intent, r.rule) == (Command.STOP, "stop-remote")
    assert r.confirmation == "You want me to stop, is this correct?"
    r = it.interpret(SICK)  # embedded: comfort, sure
    assert (r.intent, r.rule, r.overruled) == (Command.COMFORT, "local-sure", True)


@pytest.mark.parametrize(
    ("reply", "explain"),
    [
        ("```\n[EXPLAIN]\n```", True),
        ('{"tag": "[NO EXPLANATION NEEDED]"}', False),
        ("<think>red light ahead</think>[EXPLAIN]", True),
        ("Sure! [EXPLAIN]", True),
    ],
)
def test_chatty_tags_are_read(openai_server: ScriptedOpenAI, reply: str, explain: bool) -> None:
    openai_server.script = [("ok", reply)]
    d = OpenAIDecider(client(openai_server), RuleDecider()).decide(RED)
    assert (d.explain, d.fallback, d.vetoed, d.raw_reply) == (explain, False, False, reply)
    assert d.factor is (Factor.TRAFFIC_LIGHT if explain else None)


def test_an_over_eager_decider_explains_no_more_than_the_rules(
    openai_server: ScriptedOpenAI,
) -> None:
    openai_server.script = [("ok", "[EXPLAIN]")]
    eager = OpenAIDecider(client(openai_server), RuleDecider())
    rules = RuleDecider()
    ride = [row.record() for row in load_decisions(data_path(DECISIONS_JSONL))]
    remote = [eager.decide(r) for r in ride]
    local = [rules.decide(r) for r in ride]
    assert [d.explain for d in remote] == [d.explain for d in local]
    assert sum(d.explain for d in remote) == 90  # the set's records to explain
    assert sum(d.vetoed for d in remote) == len(ride) - 90
    # an empty road: every request and action, never an explanation
    empty = [
        StateRecord.model_validate(
            {"request": req, "action": a, "state": {"v_ego": v, "v_lim": 13.9}}
        )
        for req in ("fast", "comfort", "stop")
        for a in range(-3, 4)
        for v in (0.0, 6.0)
    ]
    assert sum(eager.decide(r).explain for r in empty) == 0


@pytest.mark.parametrize(
    ("reply", "used"),
    [
        ("Sure! Here's why: **the light 30 m ahead is red**, so I'm braking. \U0001f6a6", True),
        ('```json\n{"explanation": "The traffic light ahead is red, so I am braking."}\n```', True),
        ("<think>x</think>The light ahead is red, so I'm braking. We'll go soon!", True),
        ("I'm braking because of the traffic conditions.", False),  # names no factor
        ("A speed camera ahead means I'm braking at the red light.", False),
        ("A child is crossing, so I'm braking.", False),  # no pedestrian in the state
        ("The green light ahead means I'm braking.", False),
    ],
)
def test_explanations_are_cleaned_and_held_to_the_state(
    openai_server: ScriptedOpenAI, reply: str, used: bool
) -> None:
    openai_server.script = [("ok", reply)]
    e = OpenAIExplainer(client(openai_server), TemplateExplainer()).explain(RED, None)
    assert (not e.fallback) is used and e.raw_reply == reply
    assert reply_problems(e.text, RED, Factor.TRAFFIC_LIGHT) == []
    assert not set(e.text) & set("*`#{}<>\U0001f6a6") and len(e.text) <= 200


def test_a_child_on_the_crossing_is_a_pedestrian(openai_server: ScriptedOpenAI) -> None:
    rec = StateRecord.model_validate(
        {"request": "fast", "action": -2, "state": {"v_ego": 8.0, "v_lim": 13.9, "d_cross": 20.0}}
    )
    openai_server.script = [("ok", "A child is crossing 20 m ahead, so I'm braking.")]
    e = OpenAIExplainer(client(openai_server), TemplateExplainer()).explain(rec, None)
    assert (e.fallback, e.factor) == (False, Factor.PEDESTRIAN)


def test_no_factor_means_no_remote_explanation(openai_server: ScriptedOpenAI) -> None:
    e = OpenAIExplainer(client(openai_server), TemplateExplainer()).explain(EMPTY, None)
    assert e.fallback and e.factor is None and openai_server.requests == []
    assert e.text.startswith(("I'm easing off", "I'm slowing down gently", "I'm reducing"))


@pytest.mark.parametrize(
    "replies",
    [
        ["[EXPLAIN]", "A speed camera ahead, so I slowed down."],
        ["```[EXPLAIN]```", "```json\n{}\n```"],
        ["[EXPLAIN]", "<think>"],
    ],
)
def test_explain_cli_never_ends_in_a_traceback(
    openai_server: ScriptedOpenAI, tmp_path: Path, replies: list[str]
) -> None:
    config = tmp_path / "local.yaml"
    config.write_text(f"backend: openai\nopenai: {{base_url: {openai_server.base_url}}}\n")
    for name, rec in (("empty", EMPTY), ("red", RED)):
        openai_server.script = [("ok", r) for r in replies]
        case = tmp_path / f"{name}.json"
        case.write_text(rec.model_dump_json())
        args = ["explain", "--case", str(case), "--config", str(config), "--json"]
        res = runner.invoke(app, args)
        assert res.exit_code == 0, res.output
        out = json.loads(res.stdout)
        if name == "empty":
            assert (out["explain"], out["vetoed"], out["text"]) == (False, True, None)
        else:
            assert out["explain"] and out["fallback"] and "30 m" in out["text"]


def test_the_model_named_on_the_command_line_reaches_the_endpoint(
    openai_server: ScriptedOpenAI, tmp_path: Path, interpreter: EmbeddedIntentInterpreter
) -> None:
    config = tmp_path / "local.yaml"
    config.write_text(
        f"backend: openai\nopenai: {{base_url: {openai_server.base_url}, model: from-file}}\n"
    )
    openai_server.script = [("ok", "You want me to drive more carefully, is this correct?")]
    res = runner.invoke(app, ["interpret", SICK, "--config", str(config), "--json"])
    assert res.exit_code == 0, res.output
    res = runner.invoke(
        app, ["interpret", SICK, "--config", str(config), "--model", "smollm2", "--json"]
    )
    assert res.exit_code == 0, res.output
    assert [b["model"] for b in openai_server.requests] == ["from-file", "smollm2"]
