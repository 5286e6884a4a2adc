"""Self-corrections: the part of a request after its last repair marker."""

from __future__ import annotations

import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter
from explaindrive.language.intent.corrections import last_instruction


@pytest.mark.parametrize(
    ("text", "last"),
    [
        ("Faster! Oh no, actually stop, that was my street.", "stop, that was my street."),
        ("slow down, actually no, I'm late, put your foot down", "I'm late, put your foot down"),
        (
            "Stop here — no wait, wrong street, keep going and step on it.",
            "wrong street, keep going and step on it.",
        ),
        ("Go slower, I mean faster, sorry, faster.", "faster."),
        ("Take it easy... on second thought, hurry.", "hurry."),
        ("Gently please, scratch that, step on it.", "step on it."),
        ("Go faster, I mean it!", None),  # nothing but "it" after the marker
        # no marker, or nothing retracted before it
        ("No need to hurry.", None),
        ("Actually, could you slow down?", None),
        ("No, stop!", None),
        # not repairs: a negated "actually", "hold on" inside a clause, "no" before a noun
        ("I'm not, actually, in any hurry", None),
        ("I'd love to actually see some of it.", None),
        ("Slow down, hold on tight, kids", None),
        ("Hurry up, no pressure though.", None),
    ],
)
def test_last_instruction(text: str, last: str | None) -> None:
    assert last_instruction(text) == last


@pytest.mark.parametrize(
    ("text", "intent"),
    [
        ("Faster! Oh no, actually stop, that was my street.", Command.STOP),
        ("slow down, actually no, I'm late, put your foot down", Command.FAST),
    ],
)
def test_the_last_instruction_wins(
    interpreter: EmbeddedIntentInterpreter, text: str, intent: Command
) -> None:
    r = interpreter.interpret(text)
    assert r.intent is intent and r.instruction == last_instruction(text)


def test_a_marker_whose_remainder_asks_nothing_keeps_the_whole_request(
    interpreter: EmbeddedIntentInterpreter,
) -> None:
    r = interpreter.interpret("Stop the car, I mean it!")  # "it!" asks for nothing
    assert r.intent is Command.STOP and r.instruction is None
