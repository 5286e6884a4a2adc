"""Reading remote replies: every wrapper a real model adds is removed, the meaning is
held strictly (one action, one tag, plain text for the passenger)."""

from __future__ import annotations

import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.replies import (
    MAX_PASSENGER_CHARS,
    passenger_text,
    read_confirmation,
    read_decision_tag,
    unwrap,
)

COMFORT_Q = "You want me to drive more carefully, is this correct?"

CHATTY_COMFORT = [
    COMFORT_Q,
    f"Sure! {COMFORT_Q}",
    f"Of course. {COMFORT_Q}",
    f"```\n{COMFORT_Q}\n```",
    f'```json\n{{"confirmation": "{COMFORT_Q}"}}\n```',
    f'{{"confirmation": "{COMFORT_Q}"}}',
    f"<think>The passenger feels sick; stop or go faster? No: carefully.</think>\n{COMFORT_Q}",
    f"\u201c{COMFORT_Q}\u201d",
    f"'{COMFORT_Q}'",
    f"**{COMFORT_Q}**",
    "Do you want me to drive more carefully?",
    "You'd like me to slow down, right?",
    f"Drive more carefully.\n{COMFORT_Q}",
    f"{COMFORT_Q} Let me know if there is anything else I can do!",
    f"Here is the confirmation: {COMFORT_Q}",
]


@pytest.mark.parametrize("reply", CHATTY_COMFORT)
def test_every_well_formed_confirmation_is_read(reply: str) -> None:
    r = read_confirmation(reply)
    assert (r.command, r.not_a_request, r.problem) == (Command.COMFORT, False, None)


@pytest.mark.parametrize(
    ("reply", "problem"),
    [
        ("You want me to drive faster or stop, is this correct?", "more than one action"),
        ("Drive faster.\nYou want me to stop, is this correct?", "more than one action"),
        (f"{COMFORT_Q} Or would you prefer that I stop?", "more than one action"),
        ("The weather is currently sunny with a light breeze.", "names none"),
        ("I'm sorry, as an AI assistant I cannot help with that.", "names none"),
        ("", "empty reply"),
        ("<think>maybe the passenger wants me to stop", "empty reply"),
        ("I don't want me to drive faster, is this correct?", "negates the action"),
        ("The passenger is asking about how fast we go and the car would drive faster.", "not a"),
    ],
)
def test_two_actions_or_none_are_rejected(reply: str, problem: str) -> None:
    r = read_confirmation(reply)
    assert r.command is None and not r.not_a_request
    assert problem in (r.problem or "")


@pytest.mark.parametrize(
    "reply",
    ["NOT A DRIVING REQUEST", "Not a driving request.", '{"answer": "NOT A DRIVING REQUEST"}'],
)
def test_not_a_driving_request_is_read(reply: str) -> None:
    assert read_confirmation(reply).not_a_request


def test_stop_paraphrases_and_negated_speed() -> None:
    assert read_confirmation("Shall I pull over here?").command is Command.STOP
    assert read_confirmation("Would you like me to stop speeding?").command is Command.COMFORT
    assert read_confirmation("You want me to speed up, is that right?").command is Command.FAST


@pytest.mark.parametrize(
    ("reply", "tag"),
    [
        ("[EXPLAIN]", True),
        ("[NO EXPLANATION NEEDED]", False),
        ("  [explain]\n", True),
        ("```\n[EXPLAIN]\n```", True),
        ('{"decision": "[NO EXPLANATION NEEDED]"}', False),
        ("<think>it brakes for a red light [NO EXPLANATION NEEDED]?</think>[EXPLAIN]", True),
        ("Sure! [EXPLAIN]", True),
        ("NO EXPLANATION NEEDED", False),
        ("I think [EXPLAIN] is right", True),
        ("[EXPLAIN] or [NO EXPLANATION NEEDED]", None),
        ("The vehicle action is dangerous.", None),
        ("", None),
    ],
)
def test_decision_tags_in_any_wrapper(reply: str, tag: bool | None) -> None:
    assert read_decision_tag(reply) is tag


GOOD = "The light 30 m ahead is red, so I'm slowing down. We'll go again soon!"


@pytest.mark.parametrize(
    "reply",
    [
        GOOD,
        f"Sure! Here's an explanation: {GOOD}",
        f"```\n{GOOD}\n```",
        f'{{"explanation": "{GOOD}"}}',
        f"<think>red light, passenger wants speed</think>{GOOD}",
        f"\u201c{GOOD}\u201d",
        "**The light 30 m ahead is red**, so I'm slowing down. \U0001f6a6 We'll go again soon!",
        f"{GOOD} Is there anything else I can help you with?",
    ],
)
def test_explanations_reach_the_passenger_as_plain_text(reply: str) -> None:
    assert passenger_text(reply) == GOOD


def test_passenger_text_is_short() -> None:
    long = "The light ahead is red. " + "We wait. " * 40
    assert passenger_text(long) == "The light ahead is red. We wait."
    assert passenger_text("x" * (MAX_PASSENGER_CHARS + 1)) == ""
    assert passenger_text("<think>only reasoning") == ""
    assert passenger_text("# Note\n- the light is red") == "Note the light is red."


def test_unwrap_keeps_text_that_has_no_wrapper() -> None:
    assert unwrap("  plain words  ") == "plain words"
    assert unwrap('{"a": "one", "b": "two"}') == '{"a": "one", "b": "two"}'  # two fields
