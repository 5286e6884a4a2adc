"""Lexical direction cues of the embedded LLM-1 (values worked out by hand)."""

from __future__ import annotations

import pytest

from explaindrive.language.intent.cues import CUE_NAMES, N_CUES, canonical, cue_features, cue_vector


def cues(text: str) -> dict[str, float]:
    """The non-zero cues of ``text`` by name."""
    return {CUE_NAMES[i]: float(v) for i, v in enumerate(cue_vector(text)) if v}


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("Go a bit slower, please.", {"slow": 1.0}),
        ("Go a bit faster, please.", {"fast": 1.0}),
        ("Speed up.", {"fast": 1.0}),
        ("Reduce the speed.", {"slow": 1.0}),  # "speed" alone is neutral
        ("Don't go so fast.", {"neg_fast": 1.0}),
        ("No need to hurry.", {"neg_fast": 1.0}),
        ("This is too slow.", {"neg_slow": 1.0}),
        ("Stop speeding.", {"neg_fast": 1.0}),  # "stop" before a gerund negates
        ("Stop being so careful.", {"neg_slow": 1.0}),
        ("Stop dawdling.", {"too_slow": 1.0}),
        ("That stop was too abrupt.", {"stop_noun": 1.0, "too_fast": 1.0}),
        ("This is my stop.", {"stop_destination": 1.0}),
        ("Stop the car.", {"stop_request": 1.0}),
        # a motion verb after "stop" halts the car, unless a manner follows
        ("Cease moving immediately.", {"stop_request": 1.0}),
        ("Stop driving, please.", {"stop_request": 1.0}),
        ("Stop driving like a maniac.", {"too_fast": 1.0}),
        ("Cease tailgating.", {"too_fast": 1.0}),
        ("Pull over and let me out.", {"stop_request": 2.0}),
        ("Don't go any further.", {"neg_continue": 1.0}),
        # going on: a phrase, a verb, or a negated stop; negated it asks to stop
        ("Keep going, but gently.", {"continue": 1.0, "slow": 1.0}),
        ("You can go on, thanks.", {"continue": 1.0}),
        ("No need to stop, just hurry.", {"continue": 1.0, "fast": 1.0}),
        ("Please continue.", {"continue": 1.0}),
        ("Don't carry on, pull over.", {"neg_continue": 1.0, "stop_request": 1.0}),
        ("We can go on foot from here.", {"arrival": 1.0}),  # not "go on"
        ("Let's go on the ring road.", {}),  # "go on" before a clause break only
        ("Not one more block.", {"neg_continue": 1.0}),
        # the negation ends at the clause break: "late" is a plain fast cue
        ("Don't take it so easy, we're late.", {"neg_slow": 1.0, "fast": 1.0}),
        ("Play some music.", {}),
        # speeds as numbers: a cap is slower, a floor faster, "X in a Y" compares them
        ("Drop us down to about forty, please.", {"slow": 1.0}),
        ("Keep it under 30 mph.", {"slow": 1.0}),
        ("Never exceed 20 mph.", {"slow": 1.0}),  # "never" negates "exceed"
        ("Get it up to 70 on the motorway.", {"fast": 1.0}),
        ("Stop doing fifty in a thirty zone.", {"too_fast": 1.0}),
        ("We're doing 20 in a 50 limit!", {"too_slow": 1.0}),
        ("I have 2 kids.", {}),
        # idioms
        ("What's the rush?", {"neg_fast": 1.0}),
        ("Hold your horses, we have time.", {"slow": 1.0}),
        ("Chop chop!", {"fast": 1.0}),
        ("Don't floor it.", {"neg_fast": 1.0}),
        ("This will do, thanks.", {"arrival": 1.0}),
        ("Right here is fine.", {"arrival": 1.0}),  # one phrase, counted once
        ("How far is it from here?", {}),
        # places and arrivals in narration are not requests to stop
        ("We're finally here in Madrid, what a trip.", {}),
        ("The meeting ends right here at five, then dinner.", {}),
        ("We're here for a week, then off to Rome.", {}),
        ("Right here, please.", {"arrival": 1.0}),
        ("Just here is fine.", {"arrival": 1.0}),
        ("We're here!", {"arrival": 1.0}),
        # stop phrases with an object are something else
        ("Drop me a text when the match is over.", {}),
        ("Drop me at the corner.", {"stop_request": 1.0}),
        ("Pull up the map.", {}),
        ("Pull up here.", {"stop_request": 1.0}),
        ("Get out of here, really?", {}),
        ("Let me get out of the car.", {"stop_request": 1.0}),
        # "stop" after a modal with another subject is a mention
        ("The rain should stop by the afternoon.", {"stop_noun": 1.0}),
        ("You can stop here.", {"stop_request": 1.0}),
        ("We should stop.", {"stop_request": 1.0}),
        # chat spellings: "ez" is "easy", "to fast" is "too fast"
        ("ez on the pedal plz", {"slow": 1.0}),
        ("to quick man", {"neg_fast": 1.0}),
        ("I want to fast tomorrow", {"fast": 1.0}),  # "to" before a verb stays "to"
    ],
)
def test_cue_vectors(text: str, expected: dict[str, float]) -> None:
    assert cues(text) == expected


def test_typos_and_lookalikes() -> None:
    assert canonical("slowr") == "slower" and canonical("fastr") == "faster"
    assert canonical("slooow") == "slow" and canonical("hallt") == "halt"
    # real words that resemble cue words are left alone
    assert canonical("speed") == "speed" and canonical("mother") == "mother"
    assert canonical("increase") == "increase"  # not "decrease"
    assert cues("Increase the speed.") == {"fast": 1.0}
    # short common words are not read as the longer cue words they resemble
    for word in ("slot", "waving", "later", "showing"):
        assert canonical(word) == word


def test_feature_shape_and_cap() -> None:
    x = cue_features(["stop stop stop stop", "hello"])
    assert x.shape == (2, N_CUES)
    assert x[0, CUE_NAMES.index("stop_request")] == 2.0 and not x[1].any()
