"""Lexical direction cues for the embedded LLM-1: faster, slower, stop, and their negations.

Sentence embeddings place "go a bit faster" and "go a bit slower" close together and
read "stop" in "stop speeding" as a request to stop. These features make the direction
explicit: each word of a small lexicon is counted as a plain cue, or as a negated cue
when it falls in the scope of a negator ("don't", "no need to", "too", "stop"/"quit"
before a gerund). Cue words are matched with a small edit tolerance so that typed or
transcribed typos ("slowr", "fastr") still count.

Common idioms of pace ("chop chop", "hold your horses", "what's the rush?"), of arrival
("this will do", "we're here") and of going on ("keep going", "carry on") count as
phrases, chat spellings ("ez", "to fast" for "too fast") are read as the words they stand
for, and speeds given as numbers count as a direction ("under 30", "fifty in a thirty").

The features are general (word classes, negation scope, the part of speech of "stop",
idioms of English); they are combined with the sentence embedding and weighted by the
classifier. The word lists and phrases are in :mod:`explaindrive.language.intent.cue_lexicon`.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from explaindrive.language.intent.cue_lexicon import (
    ADDRESS_WORDS,
    APPROXIMATELY,
    ARRIVAL_FOLLOWERS,
    ARRIVAL_PHRASES,
    CAP_WORDS,
    CLAUSE_BREAKS,
    CLAUSE_FINAL_PHRASES,
    CONTINUE_PHRASES,
    CONTINUE_VERBS,
    CONTINUE_WORDS,
    DETERMINERS,
    DOWN_PHRASES,
    FAST_PHRASES,
    FAST_WORDS,
    FLOOR_PHRASES,
    HALT_FOLLOWERS,
    LEXICON,
    LINK_WORDS,
    MODALS,
    MOTION_GERUNDS,
    NEEDLESS_PACE_PHRASES,
    NEGATORS,
    NOT_GERUNDS,
    NOT_STOP_AFTER,
    NOT_TYPOS,
    NUMBER_WORDS,
    OVER_WORDS,
    PLACE_PHRASES,
    POSSESSIVES,
    QUIT_VERBS,
    REQUEST_SUBJECTS,
    SCOPE_TOKENS,
    SLANG,
    SLOW_PHRASES,
    SLOW_WORDS,
    STOP_PHRASES,
    STOP_VERBS,
    TOO_ADJECTIVES,
    TOO_FAST_WORDS,
    TOO_SLOW_WORDS,
    VEHICLES,
)

_TOKEN_RE = re.compile(r"[a-z']+|\d+|[.,!?;:]")

CUE_NAMES: tuple[str, ...] = (
    "fast",  # faster, hurry, late ... not negated
    "slow",  # slower, careful, gently ... not negated
    "neg_fast",  # "don't go so fast", "no need to hurry", "stop speeding", "too fast"
    "neg_slow",  # "don't be so careful", "too slow", "stop being so slow"
    "too_slow",  # "crawling", "dawdling", "like a snail"
    "too_fast",  # "reckless", "abrupt", "slamming"
    "stop_request",  # "stop", "halt", "pull over", "let me out" used as a request
    "stop_noun",  # "that stop was too abrupt", "your stops"
    "stop_destination",  # "this is my stop"
    "neg_continue",  # "no further", "don't continue", "not another block"
    "arrival",  # "we're here", "this will do", "right here is fine"
    "continue",  # "keep going", "carry on", "you can go on", "no need to stop"
)
N_CUES = len(CUE_NAMES)
_Add = Callable[[str], None]
_INDEX = {name: i for i, name in enumerate(CUE_NAMES)}


def tokenize(text: str) -> list[str]:
    """Lower-case word and punctuation tokens (curly apostrophes unified)."""
    return _TOKEN_RE.findall(text.lower().replace("\u2019", "'"))


@lru_cache(maxsize=4096)
def canonical(token: str) -> str:
    """The lexicon word ``token`` spells (allowing a typo), else ``token``.

    Repeated letters are squeezed first ("slooow" -> "slow"); tokens shorter than four
    letters must match exactly, and a typo never changes the first letter.
    """
    if token in SLANG:
        return SLANG[token]
    if token in LEXICON or token in NOT_TYPOS or len(token) < 4:
        return token
    squeezed = re.sub(r"(.)\1{2,}", r"\1", token)
    if squeezed in LEXICON:
        return squeezed
    squeezed = re.sub(r"(.)\1+", r"\1", squeezed)
    if squeezed in LEXICON:
        return squeezed
    match = difflib.get_close_matches(token, LEXICON, n=1, cutoff=0.85)
    return match[0] if match and match[0][0] == token[0] else token


def _is_gerund(token: str) -> bool:
    return token.endswith("ing") and len(token) >= 5 and token not in NOT_GERUNDS


def _in_scope(tokens: list[str], negated: list[bool], start: int) -> None:
    """Mark up to SCOPE_TOKENS words after ``start`` as negated, stopping at a clause break."""
    for j in range(start + 1, min(len(tokens), start + 1 + SCOPE_TOKENS)):
        if tokens[j] in CLAUSE_BREAKS:
            break
        negated[j] = True


def _number(token: str) -> int | None:
    if token.isdigit():
        return int(token)
    return NUMBER_WORDS.get(token)


def speed_number_cues(tokens: list[str], negated: list[bool]) -> list[str]:
    """Cues from speeds given as numbers.

    "under 30", "down to forty", "don't go over 50" -> ``slow``; "at least 60", "up to
    seventy" -> ``fast``; "fifty in a thirty" -> ``too_fast`` (``too_slow`` the other way).
    """
    out: list[str] = []
    n = len(tokens)
    for i, t in enumerate(tokens):
        value = _number(t)
        if value is None:
            continue
        j = i - 1 if i > 0 and tokens[i - 1] in APPROXIMATELY else i  # the number's start
        prev = tokens[j - 1] if j > 0 else ""
        pair = tuple(tokens[j - 2 : j]) if j >= 2 else ()
        if prev in CAP_WORDS or pair in DOWN_PHRASES or (prev in OVER_WORDS and negated[j - 1]):
            out.append("slow")
        elif pair in FLOOR_PHRASES:
            out.append("fast")
        if i + 3 < n and tokens[i + 1 : i + 3] == ["in", "a"]:
            limit = _number(tokens[i + 3])
            if limit is not None and limit != value:
                out.append("too_fast" if value > limit else "too_slow")
    return out


def _cue_tokens(text: str) -> list[str]:
    """Canonical tokens of ``text``, with "to" read as "too" before a pace adjective."""
    tokens = [canonical(t) for t in tokenize(text)]
    n = len(tokens)
    for i in range(n - 1):
        after = tokens[i + 2] if i + 2 < n else "."
        if (
            tokens[i] == "to"
            and tokens[i + 1] in TOO_ADJECTIVES
            and (after in CLAUSE_BREAKS or after in ADDRESS_WORDS)
        ):
            tokens[i] = "too"
    return tokens


def _stop_role(tokens: list[str], i: int) -> str | None:
    """The role of a stop word at ``i`` when it is not a plain request (else ``None``)."""
    n = len(tokens)
    t = tokens[i]
    nxt = tokens[i + 1] if i + 1 < n else ""
    prev = tokens[i - 1] if i > 0 else ""
    if (
        t in QUIT_VERBS
        and nxt in MOTION_GERUNDS
        and (i + 2 >= n or tokens[i + 2] in CLAUSE_BREAKS or tokens[i + 2] in HALT_FOLLOWERS)
    ):
        return "request"  # "stop moving now", "cease driving."
    if t in QUIT_VERBS and (_is_gerund(nxt) or nxt == "being"):
        return "negator"  # "stop speeding" = do not speed
    if t == "stop" and prev in POSSESSIVES:
        return "destination"
    if t in ("stop", "stops") and (prev in DETERMINERS or prev == "bus"):
        return "noun"
    subject = tokens[i - 2] if i >= 2 else ""
    if (
        t == "stop"
        and prev in MODALS
        and subject
        and subject not in REQUEST_SUBJECTS
        and subject not in CLAUSE_BREAKS
    ):
        return "noun"  # "the rain should stop": a mention, not a request
    return None


def _negation_and_stop_roles(tokens: list[str]) -> tuple[list[bool], dict[int, str]]:
    """Which tokens are negated, and the role of each stop word that is not a request."""
    negated = [False] * len(tokens)
    roles: dict[int, str] = {}
    for i, t in enumerate(tokens):
        prev = tokens[i - 1] if i > 0 else ""
        if t in NEGATORS or (t == "need" and prev == "no"):
            _in_scope(tokens, negated, i)
            continue
        role = _stop_role(tokens, i)
        if role is not None:
            roles[i] = role
        if role == "negator":
            _in_scope(tokens, negated, i)
    return negated, roles


def _phrase_applies(tokens: list[str], i: int, phrase: tuple[str, ...]) -> bool:
    """Whether ``phrase`` at ``i`` has the use its cue stands for (see the phrase lists)."""
    k = len(phrase)
    after = tokens[i + k] if i + k < len(tokens) else "."
    if phrase in CLAUSE_FINAL_PHRASES:
        return after in CLAUSE_BREAKS
    if phrase in PLACE_PHRASES:
        link = tokens[i + k + 1] if i + k + 1 < len(tokens) else ""
        return (
            after in CLAUSE_BREAKS
            or after in ARRIVAL_FOLLOWERS
            or (after in LINK_WORDS and link in ARRIVAL_FOLLOWERS)
        )
    return True


def _stop_phrase_applies(tokens: list[str], i: int, phrase: tuple[str, ...]) -> bool:
    """A stop phrase with an object is something else ("drop me a line", "get out of here")."""
    k = len(phrase)
    after = tokens[i + k] if i + k < len(tokens) else ""
    if after not in NOT_STOP_AFTER.get(phrase, frozenset()):
        return True
    # "get out of the car" is still a stop
    return phrase == ("get", "out") and any(t in VEHICLES for t in tokens[i + k : i + k + 4])


def _phrase_cues(tokens: list[str], negated: list[bool], add: _Add) -> list[bool]:
    """Count the multi-word cues; returns which tokens they consumed."""
    n = len(tokens)
    consumed = [False] * n
    for i in range(n):
        for phrases, plain, flipped in (
            (NEEDLESS_PACE_PHRASES, "neg_fast", "neg_fast"),
            (FAST_PHRASES, "fast", "neg_fast"),
            (SLOW_PHRASES, "slow", "neg_slow"),
            (ARRIVAL_PHRASES, "arrival", "arrival"),
            (CONTINUE_PHRASES, "continue", "neg_continue"),
        ):
            for phrase in phrases:
                k = len(phrase)
                if (
                    not any(consumed[i : i + k])
                    and tuple(tokens[i : i + k]) == phrase
                    and _phrase_applies(tokens, i, phrase)
                ):
                    add(flipped if negated[i] else plain)
                    consumed[i : i + k] = [True] * k
    return consumed


def _word_cues(
    tokens: list[str], negated: list[bool], roles: dict[int, str], consumed: list[bool], add: _Add
) -> None:
    """Count the single-word cues and the stop phrases."""
    for i, t in enumerate(tokens):
        if consumed[i]:
            pass
        elif t in FAST_WORDS:
            add("neg_fast" if negated[i] else "fast")
        elif t in SLOW_WORDS:
            add("neg_slow" if negated[i] else "slow")
        elif t in TOO_SLOW_WORDS:
            add("too_slow")
        elif t in TOO_FAST_WORDS:
            add("too_fast")
        elif t in CONTINUE_WORDS and negated[i]:
            add("neg_continue")
        elif t in CONTINUE_VERBS:
            add("continue")
        if t in STOP_VERBS and negated[i] and i not in roles:
            add("continue")  # "don't stop", "no need to stop", "without stopping"
        elif t in STOP_VERBS or t == "stops":
            role = roles.get(i, "noun" if t == "stops" else "request")
            if role in ("request", "noun", "destination"):
                add(f"stop_{role}" if role != "request" else "stop_request")
        for phrase in STOP_PHRASES:
            if tuple(tokens[i : i + len(phrase)]) == phrase and _stop_phrase_applies(
                tokens, i, phrase
            ):
                add("stop_request")


def cue_vector(text: str) -> NDArray[np.float32]:
    """Counts of each cue in :data:`CUE_NAMES` for one request (each capped at 2)."""
    tokens = _cue_tokens(text)
    n = len(tokens)
    negated, roles = _negation_and_stop_roles(tokens)
    v = np.zeros(N_CUES, dtype=np.float32)

    def add(name: str) -> None:
        v[_INDEX[name]] += 1.0

    consumed = _phrase_cues(tokens, negated, add)
    _word_cues(tokens, negated, roles, consumed, add)
    for name in speed_number_cues(tokens, negated):
        add(name)
    # "not one more meter", "not another inch": a negated quantity of further driving
    if n >= 2 and tokens[0] in ("not", "no") and tokens[1] in ("one", "another", "a", "further"):
        add("neg_continue")
    return np.minimum(v, 2.0)


def cue_features(texts: list[str]) -> NDArray[np.float32]:
    """Cue counts for ``texts``, shape ``(len(texts), N_CUES)``."""
    return np.stack([cue_vector(t) for t in texts]).astype(np.float32)
