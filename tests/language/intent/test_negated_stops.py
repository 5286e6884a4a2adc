"""The shipped embedded LLM-1 on negated stops, complaints about lights, stops and
arriving, and off-topic remarks with driving words: never a STOP where none is asked for,
and STOP requests still read as STOP."""

from __future__ import annotations

import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter

FAST, COMFORT, STOP = Command.FAST, Command.COMFORT, Command.STOP

# Lines written for this test, none of them in the training data.
NEGATED_STOPS = [
    ("No no, don't pull in, keep moving.", None),  # bare "keep moving": fast or comfort
    ("I'm not getting out here, keep going, gently.", COMFORT),
    ("Please don't stop yet, we're late.", FAST),
    ("This isn't my stop, carry on but take it easy.", COMFORT),
    ("Don't you dare pull over, just ease up a little.", COMFORT),
    ("We are not stopping here, hurry up.", FAST),
    ("Stopping here would be a mistake, put your foot down.", FAST),
    ("Don't bother pulling over, just hurry.", None),  # not read as a request: no command
    ("Don't let me out here, keep going nice and steady.", COMFORT),
    ("dont stop here keep going im late", FAST),
]
COMPLAINTS = [
    ("Not another red light, ugh.", None),  # a complaint: no command, never STOP
    ("We'll never arrive at this rate.", FAST),
    ("At this pace we'll arrive tomorrow.", FAST),
    ("All this stopping and starting is giving me a headache.", COMFORT),
    ("These constant stops are making me sick.", COMFORT),
    ("Red light number six, I'm going to be so late.", FAST),
    ("Too many hard stops, I'm getting a headache.", COMFORT),
]
OFF_TOPIC = [
    "Did you know the bus stop moved to the other side?",
    "The lights in that shop window are beautiful.",
    "We stopped at a lovely cafe on the way here yesterday.",
    "The rain has finally stopped.",
    "My sister arrived in Lisbon last night.",
    "Stop the music, please, it's too loud.",
    "My dad always sped up at amber lights, mum hated it.",
]


@pytest.mark.parametrize(("line", "intent"), NEGATED_STOPS + COMPLAINTS)
def test_negated_stops_and_complaints_are_read_by_their_wish(
    interpreter: EmbeddedIntentInterpreter, line: str, intent: Command | None
) -> None:
    got = interpreter.interpret(line).intent
    assert got is not STOP
    if intent is not None:
        assert got is intent


@pytest.mark.parametrize("line", OFF_TOPIC)
def test_off_topic_remarks_with_driving_words_get_no_command(
    interpreter: EmbeddedIntentInterpreter, line: str
) -> None:
    assert interpreter.interpret(line).intent is None


@pytest.mark.parametrize(
    "line",
    [
        "Stop here please.",
        "Pull over, I'm going to be sick.",
        "This is me, let me out.",
        "don't go any further, this is it",
        "Don't stop here, stop at the bakery.",
    ],
)
def test_requests_to_stop_stay_stops(interpreter: EmbeddedIntentInterpreter, line: str) -> None:
    assert interpreter.interpret(line).intent is STOP
