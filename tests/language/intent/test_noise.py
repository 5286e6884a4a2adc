import random

from explaindrive.language.intent.noise import (
    ADDRESSES,
    NEIGHBOURS,
    addressed,
    heard,
    slipped,
    typed,
)


def test_neighbours_are_the_letters_beside_on_the_row() -> None:
    assert NEIGHBOURS["q"] == "w"
    assert NEIGHBOURS["s"] == "ad"
    assert NEIGHBOURS["m"] == "n"


def test_a_typo_changes_one_or_two_words_by_one_letter_at_most() -> None:
    rng = random.Random(0)
    text = "Please drive more gently now"
    for _ in range(200):
        out = typed(text, rng)
        changed = [(a, b) for a, b in zip(text.split(), out.split(), strict=True) if a != b]
        assert out == text or 1 <= len(changed) <= 2
        assert all(abs(len(a) - len(b)) <= 1 for a, b in changed)


def test_short_words_and_empty_lines_keep_their_spelling() -> None:
    rng = random.Random(0)
    assert typed("go on", rng) == "go on"
    assert typed("!!", rng) == "!!"


def test_a_hearing_slip_is_lower_case_without_punctuation() -> None:
    rng = random.Random(3)
    for _ in range(50):
        out = heard("Pull over, PLEASE!", rng)
        assert out == out.lower() and "," not in out and "!" not in out
        words = out.split()
        if len(words) == 4:  # one word split in two
            assert out.replace(" ", "") == "pulloverplease"
        else:  # one sound of one word spelled another way
            changed = [w for w, o in zip(words, ["pull", "over", "please"], strict=True) if w != o]
            assert len(changed) == 1


def test_a_word_without_a_sound_to_swap_is_split_inside() -> None:
    # "gentle" holds none of VOWEL_SOUNDS' spellings: it is cut after its 2nd, 3rd or 4th letter
    outs = {heard("Gentle", random.Random(s)) for s in range(40)}
    assert outs == {"ge ntle", "gen tle", "gent le"}


def test_a_sound_is_swapped_either_way() -> None:
    outs = {heard("pool", random.Random(s)) for s in range(60)}
    # "pool": "oo" -> "u", or "o" -> "oa" at its first "o"; else a cut after "po"
    assert outs == {"pul", "poaol", "po ol"}


def test_a_line_without_long_words_is_only_flattened() -> None:
    assert heard("Go on, go!", random.Random(0)) == "go on go"


def test_slips_are_reproducible_from_the_seed() -> None:
    a = [slipped("Could you slow down a little?", random.Random(7)) for _ in range(3)]
    assert len(set(a)) == 1


class _Draws(random.Random):
    """A generator whose ``random()`` returns the given values in turn (the side) and whose
    ``choice`` picks the first item (the name)."""

    def __init__(self, *values: float) -> None:
        super().__init__(0)
        self._values = list(values)

    def random(self) -> float:
        return self._values.pop(0)

    def choice(self, seq):  # type: ignore[no-untyped-def, override]
        return seq[0]


def test_an_address_goes_before_or_after_the_line() -> None:
    name = ADDRESSES[0]
    assert addressed("Stop the car.", _Draws(0.1)) == f"{name}, stop the car."
    assert addressed("Stop the car.", _Draws(0.9)) == f"Stop the car, {name}."
    assert addressed("Why so slow?!", _Draws(0.9)) == f"Why so slow, {name}?!"
    assert addressed("slow down", _Draws(0.9)) == f"slow down, {name}."
    # "I" keeps its capital; an empty line stays as it is
    assert addressed("I need out here", _Draws(0.1)) == f"{name}, I need out here"
    assert addressed("  ", _Draws(0.1)) == "  "
