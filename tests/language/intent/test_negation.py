"""The rule that keeps negated stops, denied arrivals and complaints about stopping from
being read as STOP (:mod:`explaindrive.language.intent.negation`)."""

from __future__ import annotations

import pytest

from explaindrive.language.data import TEST_CSV, TRAIN_CSV, data_path
from explaindrive.language.intent.datasets import load_commands
from explaindrive.language.intent.negation import stop_is_ruled_out


@pytest.mark.parametrize(
    "line",
    [
        # a stop in the scope of a negation
        "Don't stop here, keep going.",
        "No no, don't pull in, keep moving.",
        "I'm not getting out here, keep going, gently.",
        "Don't bother pulling over, just hurry.",
        "Don't even think about pulling in, keep rolling, faster.",
        "Forget stopping, just get us there quickly.",
        "Hold off on pulling over, keep going nice and slow.",
        "Skip the stop, we're running out of time.",
        "No stopping, we're late, push on.",
        "This isn't where I get off, carry on and hurry.",
        "Not this stop, the next one, and quickly please.",
        "No, this isn't the house, keep driving and get a move on.",
        "Stopping isn't necessary, just drive more carefully.",
        "Stopping here would be a mistake, put your foot down.",
        "Don\u2019t stop here, keep going.",  # a typographic apostrophe
        # an arrival denied or out of reach
        "We'll never arrive at this rate.",
        "We're not there yet, keep going.",
        "We should have arrived twenty minutes ago.",
        # complaints about stopping
        "Not another red light, ugh.",
        "ugh not another red",
        "Red again? Seriously?",
        "All this stopping and starting is giving me a headache.",
        "Stop-start driving like this makes me carsick.",
        "Too many hard stops, I'm getting a headache.",
        "Your stops are so abrupt, I keep getting thrown forward.",
        "You stop so hard at every red light, my neck hurts.",
        "Stuck at the lights again, I'm late late late.",
        "Why are we stopped? It's green, go.",
    ],
)
def test_lines_that_do_not_ask_for_a_stop(line: str) -> None:
    assert stop_is_ruled_out(line)


@pytest.mark.parametrize(
    "line",
    [
        "Stop here please.",
        "Don't stop here, stop at the bakery.",  # a stop is still asked for
        "If you don't stop now I'll be sick.",  # a condition, not a negation
        "Why not pull over here?",  # a suggestion
        "no stop here",  # a spoken "no, stop here": a bare "no" negates nouns only
        "No, let me out here!",
        "Not another metre, let me out.",
        "We're not there yet? Oh it's here, pull over.",
        "Don't go any further, this is it.",  # no stop word is negated
        "Stop so I can get out.",
    ],
)
def test_requests_to_stop_are_not_ruled_out(line: str) -> None:
    assert not stop_is_ruled_out(line)


def test_no_labelled_stop_request_is_ruled_out() -> None:
    rows = [*load_commands(data_path(TRAIN_CSV)), *load_commands(data_path(TEST_CSV))]
    stops = [r.text for r in rows if r.label == "stop"]
    assert len(stops) > 1200
    assert [t for t in stops if stop_is_ruled_out(t)] == []
