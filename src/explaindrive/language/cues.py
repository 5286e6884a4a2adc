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
classifier.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray


def _words(text: str) -> frozenset[str]:
    return frozenset(text.split())


# Direction words. "speed" alone is neutral ("reduce the speed", "this speed scares me").
FAST_WORDS = _words(
    """fast faster fastest quick quicker quickly quicken hurry hurrying hurried rush
    rushing rushed accelerate accelerating acceleration race racing speeding
    sooner asap urgent urgently late briskly brisk throttle zoom increase raise
    hustle pronto swift swiftly speedy speedier promptly"""
)
SLOW_WORDS = _words(
    """slow slower slowly slowing slowed careful carefully cautious cautiously gentle
    gently gentler calm calmly calmer easy easier ease relax relaxed smooth smoothly
    smoother soft softly softer steady steadily comfortable comfortably safely
    decelerate decrease reduce lower less early"""
)
# Complaints about the pace: slowness words ask for more speed, recklessness words for less.
TOO_SLOW_WORDS = _words(
    """crawl crawling crawls dawdle dawdling dawdles dilly dallying snail turtle creep
    creeping crawling dragging drag poking lagging hesitating timid idling sluggish
    tortoise glacial glacier sloth funeral hearse pootling pootle lollygagging
    lollygag faffing faff dithering dither tiptoe tiptoeing"""
)
TOO_FAST_WORDS = _words(
    """reckless recklessly maniac aggressive aggressively swerving swerve tailgating
    abrupt abruptly harsh harshly jerky jerking sudden suddenly rough roughly bumpy
    slamming slam stomping tearing hurtle hurtling hurtled weaving weave zigzagging
    racetrack speedway daredevil kamikaze lurching lurch jolting jolt"""
)
# Requests to stop the trip, and words of continuing (negated: "no further").
STOP_VERBS = _words("stop halt park stopping cease")
# Verbs that forbid the action of a following gerund ("stop speeding", "quit tailgating").
_QUIT_VERBS = _words("stop quit cease")
# "stop moving" halts the car, unless a manner follows ("stop driving like a maniac").
_MOTION_GERUNDS = _words("moving driving going rolling travelling traveling")
_HALT_FOLLOWERS = _words("now immediately instantly here please right asap")
# Common words that look like cue words with a typo but are not ("speed" is neutral).
_NOT_TYPOS = _words("speed speeds sped waving wave slot slots later showing")
STOP_PHRASES: tuple[tuple[str, ...], ...] = (
    ("pull", "over"),
    ("pull", "up"),
    ("pull", "in"),
    ("let", "me", "out"),
    ("let", "me", "off"),
    ("let", "us", "out"),
    ("drop", "me"),
    ("get", "out"),
    ("get", "off"),
    ("lemme",),
    ("hop", "out"),
    ("jump", "out"),
    ("park", "it"),
)
# Stop phrases with an object are something else: "drop me a line", "pull up the map",
# "get off the phone", "get out of here!" (surprise).
_OBJECTS = _words("a an the some any your his her their my this that")
_NOT_STOP_AFTER: dict[tuple[str, ...], frozenset[str]] = {
    ("drop", "me"): _OBJECTS,
    ("pull", "up"): _OBJECTS,
    ("get", "off"): _OBJECTS,
    ("get", "out"): _OBJECTS | {"of"},
}
_VEHICLES = _words("car cab taxi vehicle")  # "get out of the car" is a stop
# "the rain should stop", "the bus will stop there": a mention, unless the car is meant
_MODALS = _words("will would should might may must could can")
_REQUEST_SUBJECTS = _words("you u ya we")
# Arrival: the passenger signals that the car is where they want to get out.
_ARRIVALS: tuple[tuple[str, ...], ...] = (
    ("we've", "arrived"),
    ("we", "have", "arrived"),
    ("this", "will", "do"),
    ("this'll", "do"),
    ("that'll", "do"),
    ("here", "is", "fine"),
    ("here's", "fine"),
    ("here", "is", "good"),
    ("here's", "good"),
    ("here", "works"),
    ("that's", "us"),
    ("this", "is", "us"),
    ("walk", "from", "here"),
    ("on", "foot", "from", "here"),
)
# Places and arrivals that are also ordinary narration ("we're here for a week", "the
# meeting ends right here at five"): they count only as the end of a clause or before an
# arrival word ("right here, please", "just here is fine").
_PLACES: tuple[tuple[str, ...], ...] = (
    ("we're", "here"),
    ("we", "are", "here"),
    ("right", "here"),
    ("just", "here"),
    ("this", "is", "it"),
    ("on", "foot"),
    ("drop", "off"),
)
ARRIVAL_PHRASES: tuple[tuple[str, ...], ...] = _ARRIVALS + _PLACES
_PLACE_PHRASES = frozenset(_PLACES)
_ARRIVAL_FOLLOWERS = _words(
    """please pls plz thanks thank thx ta cheers fine good great perfect ok okay mate driver
    do already now right here lol"""
)
_LINKS = _words("is 's will would works")  # "right here is fine", "just here will do"
CONTINUE_WORDS = _words("further farther continue continuing anymore another beyond past")
# Words and phrases that ask to go on driving (negated: "don't carry on" asks to stop).
CONTINUE_VERBS = _words("continue continuing resume")
CONTINUE_PHRASES: tuple[tuple[str, ...], ...] = (
    ("keep", "going"),
    ("keep", "driving"),
    ("keep", "moving"),
    ("keep", "on"),
    ("carry", "on"),
    ("press", "on"),
    ("go", "on"),  # only before a clause break: not "go on foot", "go on the ring road"
    ("drive", "on"),
)
_CLAUSE_FINAL_PHRASES = frozenset({("go", "on"), ("drive", "on")})
NEGATORS = _words(
    """not no don't dont never needn't neednt isn't isnt aren't arent won't wont
    shouldn't cannot can't without quit too"""
)
# "stop" before these is not a request to stop ("stop being so slow").
_DETERMINERS = _words("the that this a an your those these last next sudden hard")
_POSSESSIVES = _words("my our")
_NOT_GERUNDS = _words(
    """something nothing anything everything thing king morning evening building parking
    ring during bring string spring ceiling"""
)
SCOPE_TOKENS = 4  # a negator governs this many following words within its clause

# Multi-word direction cues; the phrase is negated when its first word is.
FAST_PHRASES: tuple[tuple[str, ...], ...] = (
    ("speed", "up"),
    ("speed", "it", "up"),
    ("speeding", "up"),
    ("pick", "up"),
    ("pick", "it", "up"),
    ("step", "on", "it"),
    ("get", "going"),
    ("get", "moving"),
    ("get", "a", "move"),
    ("move", "it"),
    ("foot", "down"),
    ("more", "speed"),
    ("go", "go"),
    ("chop", "chop"),
    ("wriggle", "on"),
    ("shift", "on"),
    ("make", "tracks"),
    ("pedal", "to", "the", "metal"),
    ("floor", "it"),
    ("on", "the", "gas"),
    ("hit", "the", "gas"),
    ("gun", "it"),
    ("get", "cracking"),
    ("shake", "a", "leg"),
    ("on", "the", "double"),
    ("hop", "to", "it"),
    ("any", "day", "now"),
    ("got", "all", "day"),
    ("open", "her", "up"),
    ("put", "your", "foot"),
    ("right", "foot"),
    ("push", "it"),
)
SLOW_PHRASES: tuple[tuple[str, ...], ...] = (
    ("take", "your", "time"),
    ("ease", "off"),
    ("ease", "up"),
    ("back", "off"),
    ("take", "it", "easy"),
    ("rein", "it", "in"),
    ("rein", "in"),
    ("hold", "your", "horses"),
    ("cool", "it"),
    ("tone", "it", "down"),
    ("dial", "it", "back"),
    ("dial", "back"),
    ("dial", "the", "speed", "back"),
    ("down", "a", "notch"),
    ("chill", "out"),
    ("steady", "on"),
)
# Questions that call the pace needless: "what's the rush?" asks for less speed.
NEEDLESS_PACE_PHRASES: tuple[tuple[str, ...], ...] = (
    ("what's", "the", "rush"),
    ("what's", "the", "hurry"),
    ("why", "the", "rush"),
    ("why", "the", "hurry"),
    ("where's", "the", "fire"),
    ("no", "rush"),
    ("no", "hurry"),
)
_LEXICON: tuple[str, ...] = tuple(
    sorted(FAST_WORDS | SLOW_WORDS | TOO_SLOW_WORDS | TOO_FAST_WORDS | STOP_VERBS | {"stops"})
)
_TOKEN_RE = re.compile(r"[a-z']+|\d+|[.,!?;:]")
_CLAUSE_BREAKS = frozenset(".,!?;:") | {"but", "and", "because"}

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


# Chat spellings of cue words, too short for the typo matcher.
SLANG = {"ez": "easy", "ezy": "easy", "fst": "fast", "slw": "slow", "qck": "quick"}
# "to fast" for "too fast": "to" before one of these, then the end of the clause or a
# form of address, is the intensifier "too".
_TOO_ADJECTIVES = _words("fast quick quickly slow slowly rough harsh jerky aggressive")
_ADDRESS = _words("man mate dude bro pal buddy please pls plz")


@lru_cache(maxsize=4096)
def canonical(token: str) -> str:
    """The lexicon word ``token`` spells (allowing a typo), else ``token``.

    Repeated letters are squeezed first ("slooow" -> "slow"); tokens shorter than four
    letters must match exactly, and a typo never changes the first letter.
    """
    if token in SLANG:
        return SLANG[token]
    if token in _LEXICON or token in _NOT_TYPOS or len(token) < 4:
        return token
    squeezed = re.sub(r"(.)\1{2,}", r"\1", token)
    if squeezed in _LEXICON:
        return squeezed
    squeezed = re.sub(r"(.)\1+", r"\1", squeezed)
    if squeezed in _LEXICON:
        return squeezed
    match = difflib.get_close_matches(token, _LEXICON, n=1, cutoff=0.85)
    return match[0] if match and match[0][0] == token[0] else token


def _is_gerund(token: str) -> bool:
    return token.endswith("ing") and len(token) >= 5 and token not in _NOT_GERUNDS


def _in_scope(tokens: list[str], negated: list[bool], start: int) -> None:
    """Mark up to SCOPE_TOKENS words after ``start`` as negated, stopping at a clause break."""
    for j in range(start + 1, min(len(tokens), start + 1 + SCOPE_TOKENS)):
        if tokens[j] in _CLAUSE_BREAKS:
            break
        negated[j] = True


# Speeds given as numbers: a cap asks for less speed, a floor for more.
_NUMBER_WORDS = {
    "ten": 10, "fifteen": 15, "twenty": 20, "thirty": 30, "forty": 40, "fifty": 50,
    "sixty": 60, "seventy": 70, "eighty": 80, "ninety": 90, "hundred": 100,
}  # fmt: skip
_CAP_WORDS = _words("under below beneath max maximum")  # "keep it under 30"
_OVER_WORDS = _words("over above exceed exceeding past beyond")  # negated: a cap
_FLOOR_PHRASES: tuple[tuple[str, ...], ...] = (("at", "least"), ("up", "to"))
_DOWN_PHRASES: tuple[tuple[str, ...], ...] = (("down", "to"), ("drop", "to"), ("back", "to"))
_APPROXIMATELY = _words("about around roughly approximately maybe say")  # "down to about 40"


def _number(token: str) -> int | None:
    if token.isdigit():
        return int(token)
    return _NUMBER_WORDS.get(token)


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
        j = i - 1 if i > 0 and tokens[i - 1] in _APPROXIMATELY else i  # the number's start
        prev = tokens[j - 1] if j > 0 else ""
        pair = tuple(tokens[j - 2 : j]) if j >= 2 else ()
        if prev in _CAP_WORDS or pair in _DOWN_PHRASES or (prev in _OVER_WORDS and negated[j - 1]):
            out.append("slow")
        elif pair in _FLOOR_PHRASES:
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
            and tokens[i + 1] in _TOO_ADJECTIVES
            and (after in _CLAUSE_BREAKS or after in _ADDRESS)
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
        t in _QUIT_VERBS
        and nxt in _MOTION_GERUNDS
        and (i + 2 >= n or tokens[i + 2] in _CLAUSE_BREAKS or tokens[i + 2] in _HALT_FOLLOWERS)
    ):
        return "request"  # "stop moving now", "cease driving."
    if t in _QUIT_VERBS and (_is_gerund(nxt) or nxt == "being"):
        return "negator"  # "stop speeding" = do not speed
    if t == "stop" and prev in _POSSESSIVES:
        return "destination"
    if t in ("stop", "stops") and (prev in _DETERMINERS or prev == "bus"):
        return "noun"
    subject = tokens[i - 2] if i >= 2 else ""
    if (
        t == "stop"
        and prev in _MODALS
        and subject
        and subject not in _REQUEST_SUBJECTS
        and subject not in _CLAUSE_BREAKS
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
    if phrase in _CLAUSE_FINAL_PHRASES:
        return after in _CLAUSE_BREAKS
    if phrase in _PLACE_PHRASES:
        link = tokens[i + k + 1] if i + k + 1 < len(tokens) else ""
        return (
            after in _CLAUSE_BREAKS
            or after in _ARRIVAL_FOLLOWERS
            or (after in _LINKS and link in _ARRIVAL_FOLLOWERS)
        )
    return True


def _stop_phrase_applies(tokens: list[str], i: int, phrase: tuple[str, ...]) -> bool:
    """A stop phrase with an object is something else ("drop me a line", "get out of here")."""
    k = len(phrase)
    after = tokens[i + k] if i + k < len(tokens) else ""
    if after not in _NOT_STOP_AFTER.get(phrase, frozenset()):
        return True
    # "get out of the car" is still a stop
    return phrase == ("get", "out") and any(t in _VEHICLES for t in tokens[i + k : i + k + 4])


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
