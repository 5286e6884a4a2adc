"""Lines that mention stopping or arriving without asking for a stop.

Sentence embeddings place "don't stop here, keep going" and "ugh, another red light"
next to "stop here": the words are the same, the wish is the opposite. Three patterns
catch them:

* a stop in the scope of a negation: "don't pull in here", "I'm not getting out here",
  "no stopping yet", "don't bother pulling over", "forget about stopping", "this isn't my
  stop", "this isn't where I get off", "not here, keep driving", "stopping isn't
  necessary". A negation that opens a condition or a suggestion ("if you don't stop
  now...", "why not stop here?") does not count, and a bare "no" negates only a noun or a
  gerund ("no stopping"), since "no stop here" is a spoken "no, stop here";
* an arrival that is denied or out of reach: "we're not there yet", "we'll never arrive",
  "at this rate", "we should have arrived by now";
* a complaint about stopping: "another red light", "red again", "we keep stopping at
  every junction", "all this stopping and starting", "these sudden stops", "you stop so
  hard".

:func:`stop_is_ruled_out` is true when one of them matches and no plain request to stop
is left in the rest of the line ("don't stop here, stop at the bakery" still asks for a
stop). The embedded interpreter then does not read the line as STOP and chooses among
the other readings.
"""

from __future__ import annotations

import re

_I = re.IGNORECASE
# A negation of the verb that follows (after at most three gap words).
_NEG = (
    r"(?:don'?t|do not|didn'?t|did not|never|no need to|no point in|not|won'?t|will not"
    r"|never mind|forget(?: about)?|skip|hold off(?: on)?)"
)
_STOP_ACT = (
    r"(?:stop(?:ping)?|pull(?:ing)? (?:in|over|up)|halt(?:ing)?|park(?:ing)?"
    r"|drop(?:ping)? (?:me|us)(?: off)?|let(?:ting)? (?:me|us) (?:out|off)"
    r"|get(?:ting)? (?:out|off)|hop(?:ping)? (?:out|off)|brak(?:e|ing))"
)
# The noun and gerund forms that a bare "no" can negate ("no stopping", "no pulling over").
_STOP_NOUN = (
    r"(?:stops|stopping|pulling (?:in|over|up)|halting|parking|dropping (?:me|us) off"
    r"|letting (?:me|us) (?:out|off)|getting (?:out|off)|braking)"
)
# words that may stand between the negation and the verb: "don't you dare stop", "I never
# asked you to stop", "no need to pull over", "don't bother pulling in"
_GAP = (
    r"(?:just|even|really|need|needs|want|wanna|gonna|going|got|have|has|to|be|you|me|us"
    r"|yet|ever|dare|say|said|ask|asked|tell|told|plan|planning|mean|meant|bother|think"
    r"|about|worry|the|a|any|for|with)"
)
# Conditions and suggestions: "if you don't stop now", "why not pull over?"
_NOT_A_NEGATION = r"(?<!why )(?<!why you )(?<!if you )(?<!if we )(?<!unless you )"
_NEGATED = (
    re.compile(rf"{_NOT_A_NEGATION}\b{_NEG}\s+(?:{_GAP}\s+){{0,3}}{_STOP_ACT}\b", _I),
    re.compile(rf"\bno\s+(?:more\s+)?{_STOP_NOUN}\b", _I),
    re.compile(
        r"\b(?:isn'?t|is not|not|wasn'?t)\s+(?:my|our|the right|the|this|that)\s+stop\b", _I
    ),
    re.compile(
        r"\b(?:isn'?t|is not|not)\s+(?:where (?:i|we) (?:get|hop|want to get) (?:out|off)"
        r"|the (?:right )?(?:place|house|spot|building|address|street))\b",
        _I,
    ),
    re.compile(
        r"\bnot (?:here|this (?:one|corner|street|spot|block))\b(?=.*\b(?:keep|carry on|drive on"
        r"|go on|continue|move on|moving|going|driving)\b)",
        _I,
    ),
    re.compile(
        r"\b(?:stopping|pulling (?:in|over)|a stop)\b(?:\s+(?:here|now|yet|for me|at all))?\s+"
        r"(?:isn'?t|is not|would be|is|'s)\s+(?:really\s+)?(?:necessary|needed|an option"
        r"|required|a (?:bad idea|mistake)|pointless|unnecessary)\b",
        _I,
    ),
)
_ARRIVAL = (
    re.compile(
        r"\b(?:not|never|aren'?t|isn'?t|won'?t)\s+(?:\w+\s+)?(?:there|arrive|arriving"
        r"|get(?:ting)? there)\b",
        _I,
    ),
    re.compile(r"\bat this (?:rate|pace|speed)\b", _I),
    re.compile(r"\bshould(?: have|'ve) (?:arrived|been there)\b", _I),
)
_COMPLAINT = (
    re.compile(
        r"\b(?:another|yet another|every(?: single)?|all (?:these|those|the)|so many|each)\s+"
        r"(?:(?:single|bloody|damn|stupid|sudden|red|traffic|of these|of the)\s+){0,2}"
        r"(?:lights?|signals?|stops?|junctions?|stop-and-go|reds?)\b",
        _I,
    ),
    re.compile(r"\b(?:red|stopped|stopping|stop)\s+(?:light\s+)?again\b", _I),
    re.compile(r"\bkeep (?:on )?(?:stopping|braking)\b", _I),
    re.compile(
        r"\b(?:stop[- ]start(?:ing)?|stop(?:ping)? and start(?:ing)?|start(?:ing)? and "
        r"stop(?:ping)?|stop-and-go)\b",
        _I,
    ),
    re.compile(
        r"\b(?:all|so much|constant|endless)\s+(?:this |the |that )?(?:stopping|braking)\b", _I
    ),
    re.compile(
        r"\b(?:hard|sudden|harsh|jerky|abrupt|sharp|bumpy|rough|violent|constant|endless"
        r"|jolting|your)\s+stops\b",
        _I,
    ),
    re.compile(
        r"\b(?:stop|stops|stopping|stopped|halt|brake|brakes|braking)\s+(?:so|too|way too)\s+"
        r"(?:hard|suddenly|abruptly|sharply|harshly|late|jerkily|violently)\b",
        _I,
    ),
    re.compile(
        r"\b(?:stuck|caught|waiting)\s+at\s+(?:the|every|another|all the)\s+"
        r"(?:lights?|reds?|signals?)\b",
        _I,
    ),
    re.compile(r"\bwhy (?:are|have) we (?:stopped|stopping)\b", _I),
)
# What still asks for a stop once the spans above are taken out.
_STOP_REQUEST = re.compile(
    r"\b(?:stop|halt|pull over|pull in|pull up|let me (?:out|off)|drop me(?: off)?"
    r"|get (?:out|off) here|park)\b",
    _I,
)


def stop_is_ruled_out(text: str) -> bool:
    """Whether ``text`` mentions stopping or arriving only negated, out of reach, or in a
    complaint (see the module docstring)."""
    rest = text.replace("\u2019", "'")
    found = False
    for pattern in (*_NEGATED, *_ARRIVAL, *_COMPLAINT):
        rest, n = pattern.subn(" ", rest)
        found = found or n > 0
    return found and not _STOP_REQUEST.search(rest)
