"""Self-corrections: the passenger's last instruction is the one that counts.

Spoken requests often repair themselves: "Faster! Oh no, actually stop, that was my
street." or "slow down, actually no, I'm late, put your foot down". A repair marker
("actually", "no wait", "scratch that", "on second thought", "I mean", a bare "no,"...)
that opens a clause retracts what came before it. :func:`last_instruction` returns the
part of a request after its last such marker; the embedded LLM-1 reads that part on its
own and uses it whenever it asks for a command (see
:class:`~explaindrive.language.backends.embedded.EmbeddedIntentInterpreter`).

The markers are general features of spoken English repairs, not phrases of a split.
"""

from __future__ import annotations

import re

# Tokens with their character offsets; dashes and ellipses count as clause breaks.
_TOKEN_RE = re.compile(r"[a-z']+|\d+|\.\.\.|[.,!?;:\u2014\u2013]|(?<=\s)-(?=\s)")
_BREAKS = frozenset({".", ",", "!", "?", ";", ":", "...", "\u2014", "\u2013", "-"})
# Fillers that may stand between a clause break and a marker ("Faster! Oh no, actually ...").
_FILLERS = frozenset({"oh", "um", "uh", "er", "erm", "hmm", "ah", "oops", "well", "so", "and"})
# A remainder of only these words asks for nothing ("I mean it!", "no, please").
_EMPTY = frozenset({"it", "that", "this", "so", "too", "please", "pls", "thanks", "ok", "okay"})
_NEGATORS = frozenset({"not", "never"})  # and words ending in "n't"; a bare "no" is a repair

# Markers that retract the clause before them wherever they open a clause.
REPAIR_MARKERS: tuple[tuple[str, ...], ...] = (
    ("on", "second", "thoughts"),
    ("on", "second", "thought"),
    ("second", "thoughts"),
    ("correction",),
    ("change", "of", "plan"),
    ("scratch", "that"),
    ("forget", "that"),
    ("forget", "it"),
    ("never", "mind"),
    ("nevermind",),
    ("or", "rather"),
    ("no", "wait"),
    ("wait", "no"),
    ("i", "meant"),
    ("i", "mean"),
    ("actually",),
)
# Markers that retract only when a clause break follows them ("no, stop" but not "no
# need to stop"; "hang on, stop" but not "hang on tight").
BREAK_MARKERS: tuple[tuple[str, ...], ...] = (
    ("hang", "on"),
    ("hold", "on"),
    ("wait",),
    ("sorry",),
    ("no",),
)


def _tokens(text: str) -> list[re.Match[str]]:
    return list(_TOKEN_RE.finditer(text.lower().replace("\u2019", "'")))


def _opens_clause(words: list[str], i: int) -> bool:
    """Whether position ``i`` starts a clause (after fillers and earlier markers)."""
    j = i - 1
    while j >= 0 and (words[j] in _FILLERS or words[j] in ("no", "wait", "sorry", "actually")):
        j -= 1
    return j < 0 or words[j] in _BREAKS


def _marker_end(words: list[str], i: int) -> int | None:
    """Index just past a repair marker starting at ``i``, or ``None``."""
    for marker in REPAIR_MARKERS:
        k = len(marker)
        if tuple(words[i : i + k]) == marker:
            if marker == ("actually",) and _negated_before(words, i):
                return None  # "I'm not, actually, in a hurry"
            return i + k
    for marker in BREAK_MARKERS:
        k = len(marker)
        if tuple(words[i : i + k]) == marker and i + k < len(words) and words[i + k] in _BREAKS:
            return i + k
    return None


def _negated_before(words: list[str], i: int) -> bool:
    """A negator within the two words before ``i`` (clause breaks skipped)."""
    before = [w for w in words[max(0, i - 3) : i] if w not in _BREAKS]
    return any(w in _NEGATORS or w.endswith("n't") for w in before[-2:])


def last_instruction(text: str) -> str | None:
    """The part of ``text`` after its last repair marker, or ``None`` without one.

    ``None`` also when nothing with a word follows the marker, or when the marker opens
    the request (then the whole request is the last instruction).

    Examples:
        ``"Faster! Oh no, actually stop, that was my street."`` ->
        ``"stop, that was my street."``; ``"Go faster, I mean it!"`` -> ``None``;
        ``"No need to hurry."`` -> ``None``.
    """
    found = _tokens(text)
    words = [m.group(0) for m in found]
    first: int | None = None
    cut: int | None = None
    for i in range(len(words)):
        if not _opens_clause(words, i):
            continue
        end = _marker_end(words, i)
        if end is not None and any(w[0].isalnum() and w not in _EMPTY for w in words[end:]):
            first = i if first is None else first
            cut = end
    if first is None or cut is None or all(w in _BREAKS or w in _FILLERS for w in words[:first]):
        return None  # no marker, or nothing but fillers before the first one
    start = next(k for k in range(cut, len(words)) if words[k][0].isalnum())
    return text[found[start].start() :].strip()
