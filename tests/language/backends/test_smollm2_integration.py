"""A real model behind the ``openai`` backend: SmolLM2-135M-Instruct served by llama.cpp
(``xllamacpp``) on 127.0.0.1. A model this small answers badly; what is checked is what
the passenger gets: only template questions, no more explanations than the rule engine
gives, explanations true of the state, and every reply counted as accepted, fallen back
or vetoed. ``pytest -s`` prints the counts."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import RuleDecider
from explaindrive.language.backends.local_server import LocalModelUnavailableError, start_server
from explaindrive.language.backends.replies import MAX_PASSENGER_CHARS
from explaindrive.language.config import LanguageConfig, OpenAIConfig
from explaindrive.language.explanation.decision import Factor
from explaindrive.language.explanation.grounding import reply_problems
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.interpreter import REPHRASE_MESSAGE, format_confirmation
from explaindrive.language.stack import LanguageStack, make_language_stack

pytestmark = [pytest.mark.slow, pytest.mark.models]

TEMPLATES = {format_confirmation(c) for c in Command} | {REPHRASE_MESSAGE}
REQUESTS = [  # (text, what the passenger must never get)
    ("Please go faster, I'm late for my train.", Command.COMFORT),
    ("I feel sick, could you drive more gently?", Command.FAST),
    ("Stop the car right here, please!", None),
    ("What's the weather like tomorrow?", Command.FAST),
    ("Not another red light, ugh.", Command.STOP),
    ("No no, don't pull in here, keep moving.", Command.STOP),
    ("Tell me a joke about cats.", Command.STOP),
    ("There's a cake on my lap, careful please.", Command.FAST),
]


def record(request: str, action: int, **state: float | str) -> StateRecord:
    return StateRecord.model_validate(
        {"request": request, "action": action, "state": {"v_ego": 9.0, "v_lim": 13.9, **state}}
    )


RIDE = [  # a scripted ride: what the decider sees step by step
    record("fast", 0),
    record("fast", -2, d_tl=30.0, tl_state="red"),
    record("fast", -1),  # empty road: nothing to explain
    record("comfort", -3, d_cross=12.0),
    record("comfort", 1),
    record("fast", -3, d_lead=40.0, dv=3.0),
    record("stop", -2),
    record("fast", 0, v_ego=0.0, d_tl=4.0, tl_state="red"),
]


@pytest.fixture(scope="module")
def smollm2() -> Iterator[LanguageStack]:
    try:
        server = start_server(threads=2)
    except LocalModelUnavailableError as exc:
        pytest.skip(f"{exc} (make dev-install installs it)")
    remote = OpenAIConfig(base_url=server.base_url, model="smollm2", api_key="none", timeout_s=20)
    yield make_language_stack("openai", LanguageConfig(openai=remote)).load()
    server.close()


def test_smollm2_through_the_openai_backend(smollm2: LanguageStack) -> None:
    counts = {"accepted": 0, "fallback": 0, "vetoed": 0, "not_asked": 0}
    for text, never in REQUESTS:
        r = smollm2.interpreter.interpret(text)
        assert r.confirmation in TEMPLATES, (text, r)
        if never is not None and r.intent is never:
            # the written policy: a remote STOP on an unsure embedded reading is asked back
            assert (never, r.rule) == (Command.STOP, "stop-remote"), (text, r)
            assert r.confirmation == format_confirmation(Command.STOP), (text, r)
        if text.startswith("Stop the car"):
            assert (r.intent, r.stop_lane, r.raw_reply) == (Command.STOP, True, None)
        key = "fallback" if r.fallback else "vetoed" if r.overruled else "accepted"
        counts[key if r.raw_reply is not None or r.fallback else "not_asked"] += 1

    rules = RuleDecider()
    tags = {"accepted": 0, "fallback": 0, "vetoed": 0}
    shown: list[str] = []
    for rec in RIDE:
        d = smollm2.decider.decide(rec)
        assert not d.explain or rules.decide(rec).explain, rec  # never more than the rules
        tags["fallback" if d.fallback else "vetoed" if d.vetoed else "accepted"] += 1
        if d.explain:
            e = smollm2.explainer.explain(rec, d.factor)
            assert reply_problems(e.text, rec, d.factor) == [], e
            assert len(e.text) <= MAX_PASSENGER_CHARS and not set(e.text) & set("*#`{}<>")
            shown.append(f"{'template' if e.fallback else 'model'}: {e.text}")
    red = record("fast", -2, d_tl=30.0, tl_state="red")
    texts = [smollm2.explainer.explain(red, Factor.TRAFFIC_LIGHT) for _ in range(4)]
    for e in texts:
        assert reply_problems(e.text, red, Factor.TRAFFIC_LIGHT) == [], e
    used = sum(not e.fallback for e in texts)
    print(
        f"\nSmolLM2 LLM-1 {counts}; LLM-2 {tags}; LLM-3 {used} of {len(texts)} used, "
        f"{len(texts) - used} fell back"
    )
    for line in shown:
        print(line)
    assert sum(counts.values()) == len(REQUESTS) and sum(tags.values()) == len(RIDE)
