"""Typing and hearing slips, applied to labelled lines while LLM-1 is fine-tuned.

A passenger types in a hurry ("pls be gentel") and speech recognition writes what it heard
("pool over", "slow er"): a line's reading must not hang on its spelling. Each slip keeps
the line's meaning, so the line keeps its label:

* a typo in one or two words: a letter dropped, doubled, swapped with the next, or replaced
  by a neighbour on the keyboard;
* a hearing slip: the line in lower case without punctuation, as a recogniser writes it,
  with one word split in two or one vowel sound written another way.

A passenger may also address someone ("Jonas, stop the car", "slow down, mate"):
:func:`addressed` adds a name or a form of address to a line, which keeps its label too.
Everyday dialogue is full of names ("Pipe down in there, Hutz."), so a model that never saw
a request with one can learn that a name means no request (docs/language.md, fine-tuning,
has a case).
"""

from __future__ import annotations

import random
import re

_ROWS = ("qwertyuiop", "asdfghjkl", "zxcvbnm")
NEIGHBOURS: dict[str, str] = {}
"""The letters beside each letter on a QWERTY keyboard (same row)."""
for _row in _ROWS:
    for _i, _c in enumerate(_row):
        NEIGHBOURS[_c] = _row[max(0, _i - 1) : _i] + _row[_i + 1 : _i + 2]

VOWEL_SOUNDS = (("u", "oo"), ("ee", "ea"), ("ai", "ay"), ("o", "oa"), ("er", "a"), ("i", "ee"))
"""Pairs of spellings of one sound a recogniser may swap, either way round."""

_WORD = re.compile(r"[A-Za-z]{3,}")


def _typo(word: str, rng: random.Random) -> str:
    i = rng.randrange(len(word))
    kind = rng.randrange(4)
    if kind == 0:
        return word[:i] + word[i + 1 :]
    if kind == 1:
        return word[: i + 1] + word[i:]
    if kind == 2 and i + 1 < len(word):
        return word[:i] + word[i + 1] + word[i] + word[i + 2 :]
    near = NEIGHBOURS.get(word[i].lower(), "")
    return word[:i] + rng.choice(near) + word[i + 1 :] if near else word


def typed(text: str, rng: random.Random) -> str:
    """``text`` with a typo in one or two of its words of three letters or more."""
    words = list(_WORD.finditer(text))
    if not words:
        return text
    chosen = rng.sample(words, min(len(words), rng.choice((1, 1, 2))))
    out, last = [], 0
    for m in sorted(chosen, key=lambda m: m.start()):
        out += [text[last : m.start()], _typo(m.group(), rng)]
        last = m.end()
    return "".join(out) + text[last:]


def heard(text: str, rng: random.Random) -> str:
    """``text`` as a recogniser may write it: lower case, no punctuation, and one word
    split in two or with a vowel sound spelled another way."""
    plain = " ".join(re.sub(r"[^\w\s']", " ", text.lower()).split())
    words = plain.split(" ")
    long = [i for i, w in enumerate(words) if len(w) >= 4]
    if not long:
        return plain
    i = rng.choice(long)
    w = words[i]
    swaps = [(a, b) for a, b in VOWEL_SOUNDS if a in w] + [
        (b, a) for a, b in VOWEL_SOUNDS if b in w
    ]
    if swaps and rng.random() < 0.5:
        a, b = rng.choice(swaps)
        words[i] = w.replace(a, b, 1)
    else:
        cut = rng.randrange(2, len(w) - 1)
        words[i] = w[:cut] + " " + w[cut:]
    return " ".join(words)


def slipped(text: str, rng: random.Random) -> str:
    """``text`` with a typing slip or a hearing slip, chosen at random."""
    return typed(text, rng) if rng.random() < 0.5 else heard(text, rng)


ADDRESSES = (
    "Jonas", "Priya", "Maria", "Tom", "Aisha", "Ken", "Sofia", "Chen", "Olga", "Omar",
    "Grace", "Sam", "Luca", "Noor", "Hiro", "Femi", "Zoe", "Raj", "Ines", "Pete",
    "Mum", "Dad", "mate", "buddy", "love", "sir", "madam", "driver", "Computer", "car",
)  # fmt: skip
"""Names and forms of address :func:`addressed` draws from."""

_FIRST_PERSON = re.compile(r"^I\b")
_END = re.compile(r"^(.*?)([.!?]*)$", re.DOTALL)


def addressed(text: str, rng: random.Random) -> str:
    """``text`` addressed to someone: a name or a form of address before it ("Jonas, stop
    the car.") or after it ("Stop the car, Jonas.")."""
    name = rng.choice(ADDRESSES)
    line = text.strip()
    if not line:
        return text
    if rng.random() < 0.5:
        first = line if _FIRST_PERSON.match(line) else line[0].lower() + line[1:]
        return f"{name}, {first}"
    match = _END.match(line)
    assert match is not None  # the pattern matches any string
    body, end = match.groups()
    return f"{body}, {name}{end or '.'}"
