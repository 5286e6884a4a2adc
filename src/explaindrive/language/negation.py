"""Lines that mention stopping without asking for a stop.

Sentence embeddings place "don't stop here, keep going" and "ugh, another red light"
next to "stop here": the words are the same, the wish is the opposite. Two patterns
catch them:

* a negated stop: "don't pull in here", "I'm not getting out here", "no stopping yet",
  "this isn't my stop", "not here, keep driving";
* a complaint about stopping: "another red light", "red again", "we keep stopping at
  every junction", "all these sudden stops".

:func:`stop_is_ruled_out` is true when one of them matches and no plain request to stop
is left in the rest of the line ("don't stop here, stop at the bakery" still asks for a
stop). The embedded interpreter then does not read the line as STOP and chooses among
the other readings.
"""

from __future__ import annotations

import re

_I = re.IGNORECASE
_NEG = r"(?:don'?t|do not|didn'?t|did not|never|no need to|not|no|won'?t|will not)"
_STOP_ACT = (
    r"(?:stop(?:ping)?|pull(?:ing)? (?:in|over|up)|halt(?:ing)?|park(?:ing)?"
    r"|drop(?:ping)? (?:me|us)(?: off)?|let(?:ting)? (?:me|us) (?:out|off)"
    r"|get(?:ting)? (?:out|off)|hop(?:ping)? (?:out|off)|brak(?:e|ing))"
)
# words that may stand between the negation and the verb: "don't you dare stop", "I never
# asked you to stop", "no need to pull over"
_GAP = (
    r"(?:just|even|really|need|needs|want|wanna|gonna|going|got|have|has|to|be|you|me|us"
    r"|yet|ever|dare|say|said|ask|asked|tell|told|plan|planning|mean|meant)"
)
_NEGATED = (
    re.compile(rf"(?<!why )(?<!why you )\b{_NEG}\s+(?:{_GAP}\s+){{0,3}}{_STOP_ACT}\b", _I),
    re.compile(r"\b(?:isn'?t|is not|not|wasn'?t)\s+(?:my|our|the right|the)\s+stop\b", _I),
    re.compile(
        r"\bnot (?:here|this (?:one|corner|street|spot|block))\b(?=.*\b(?:keep|carry on|drive on"
        r"|go on|continue|move on|moving|going|driving)\b)",
        _I,
    ),
)
_COMPLAINT = (
    re.compile(
        r"\b(?:another|yet another|every(?: single)?|all (?:these|those|the)|so many|each)\s+"
        r"(?:(?:single|bloody|damn|stupid|sudden|red|traffic|of these|of the)\s+){0,2}"
        r"(?:lights?|signals?|stops?|junctions?|stop-and-go)\b",
        _I,
    ),
    re.compile(r"\b(?:red|stopped|stopping|stop)\s+(?:light\s+)?again\b", _I),
    re.compile(r"\bkeep (?:on )?(?:stopping|braking)\b", _I),
)
# What still asks for a stop once the spans above are taken out.
_STOP_REQUEST = re.compile(
    r"\b(?:stop|halt|pull over|pull in|pull up|let me (?:out|off)|drop me(?: off)?"
    r"|get (?:out|off) here|park)\b",
    _I,
)


def stop_is_ruled_out(text: str) -> bool:
    """Whether ``text`` mentions stopping only negated or in a complaint (see the module
    docstring)."""
    rest = text
    found = False
    for pattern in (*_NEGATED, *_COMPLAINT):
        rest, n = pattern.subn(" ", rest)
        found = found or n > 0
    return found and not _STOP_REQUEST.search(rest)
