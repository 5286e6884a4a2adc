"""Reading what a remote model said: tolerant of form, strict in meaning.

Real models wrap their answers: a reasoning block (``<think>...</think>``), a code
fence, a JSON object with one text field, a leading "Sure!" or "Of course.", quotes of
any kind, a closing remark. :func:`unwrap` removes all of that. What is left is then read
for its meaning only:

* LLM-1 (:func:`read_confirmation`): the confirmation must name exactly one of the three
  actions (the template, a close paraphrase such as "Do you want me to drive more
  carefully?", or the paper's two-line form of an instruction followed by the question),
  or say that the line is not a driving request (:data:`NOT_A_REQUEST`). A reply that
  names two actions, or none, is rejected.
* LLM-2 (:func:`read_decision_tag`): exactly one of the two tags, with or without
  brackets; both or neither is rejected.
* LLM-3 (:func:`passenger_text`): plain text for the passenger, at most two sentences
  and :data:`MAX_PASSENGER_CHARS` characters, without markup or emoji.

The passenger never sees a remote reply as it came: a confirmation is always the
template for the command read from it, and an explanation is the cleaned text.
"""

from __future__ import annotations

import json
import re
import unicodedata
from dataclasses import dataclass

from explaindrive.commands import Command

NOT_A_REQUEST = "NOT A DRIVING REQUEST"
"""What LLM-1 answers for a line that is not about how to drive (the prompt asks for it)."""
MAX_PASSENGER_CHARS = 200  # an explanation longer than this is cut at a sentence end
MAX_SENTENCES = 2

_I = re.IGNORECASE
_THINK = re.compile(r"<(think|thinking|reasoning|reflection)>.*?</\1>", _I | re.S)
_OPEN_THINK = re.compile(r"<(think|thinking|reasoning|reflection)>.*", _I | re.S)
_CLOSE_THINK = re.compile(r"^.*?</(think|thinking|reasoning|reflection)>", _I | re.S)
_FENCE = re.compile(r"```[a-zA-Z0-9_-]*[ \t]*\n?(.*?)```", re.S)
_QUOTES = {
    "\u201c": '"',
    "\u201d": '"',
    "\u201e": '"',
    "\u00ab": '"',
    "\u00bb": '"',
    "\u2018": "'",
    "\u2019": "'",
    "\u201a": "'",
    "\u2039": "'",
    "\u203a": "'",
    "`": "'",
}
_QUOTE_CHARS = "\"'"
_ACK = re.compile(
    r"^\s*(?:(?:sure|of course|certainly|absolutely|okay|ok|alright|all right|got it|"
    r"understood|no problem|great|happy to help|yes|right)\b[\s!.,:;-]*)+",
    _I,
)
_PREAMBLE = re.compile(
    r"^\s*(?:here(?:'s| is) (?:the|my|a|your)? ?[\w\s-]{0,40}?|"
    r"(?:confirmation|answer|response|reply|output|explanation|decision|tag|assistant)"
    r"(?: question)?)\s*:\s*",
    _I,
)
_MARKUP = re.compile(r"(\*\*|__|\*|~~|^#+\s*|^\s*[-*•]\s+|^\s*>\s*)", re.M)


def unwrap(text: str) -> str:
    """The reply without reasoning blocks, code fences, a JSON wrapper, quotes of any kind
    and leading acknowledgements ("Sure!", "Of course.", "Here is the confirmation:")."""
    t = _THINK.sub(" ", text)
    t = _CLOSE_THINK.sub(" ", t)  # the opening tag was cut off (or sent as a prefix)
    t = _OPEN_THINK.sub(" ", t)  # reasoning that never ended: nothing after it counts
    fenced = _FENCE.findall(t)
    if fenced:
        t = "\n".join(fenced)
    t = t.replace("```", " ")
    t = _from_json(t.strip())
    for curly, straight in _QUOTES.items():
        t = t.replace(curly, straight)
    t = _MARKUP.sub("", t)
    for _ in range(3):  # "Sure! Here is the confirmation: ..." peels in two steps
        t = _strip_quotes(_PREAMBLE.sub("", _ACK.sub("", t)))
    return t.strip()


def _from_json(t: str) -> str:
    """The text inside a JSON string, or inside an object with one text field."""
    if not t or t[0] not in '{["':
        return t
    try:
        value = json.loads(t)
    except ValueError:
        return t
    while isinstance(value, list) and len(value) == 1:
        value = value[0]
    if isinstance(value, str):
        return value
    if isinstance(value, dict):
        texts = [v for v in value.values() if isinstance(v, str) and v.strip()]
        if len(texts) == 1:
            return texts[0]
    return t


def _strip_quotes(t: str) -> str:
    t = t.strip()
    while len(t) >= 2 and t[0] in _QUOTE_CHARS and t[-1] in _QUOTE_CHARS:
        t = t[1:-1].strip()
    if t.count('"') == 1:  # a quote opened and never closed
        t = t.replace('"', "")
    return t


# --- LLM-1: the confirmation -------------------------------------------------------------

_ACTION_WORDS: dict[Command, re.Pattern[str]] = {
    Command.FAST: re.compile(
        r"\b(drive faster|go faster|faster|speed up|speeding up|hurry( up)?|pick up the pace"
        r"|accelerate|quicker|more quickly|step on it)\b",
        _I,
    ),
    Command.COMFORT: re.compile(
        r"\b(more carefully|carefully|careful|slow(er|ly)?( down)?|slowing down|gentl[ey]\w*"
        r"|smooth\w*|more safely|safer|more comfortabl\w+|calmer|ease off|take it easy"
        r"|reduce (our |the )?speed|stop (speeding|rushing|racing))\b",
        _I,
    ),
    Command.STOP: re.compile(
        r"(?<!non-)\b(stop|stopping|halt|pull over|pull in|come to a stop|let you out)\b"
        r"(?!\s+(speeding|rushing|racing|driving (so )?fast|being))",
        _I,
    ),
}
# A confirmation asks the passenger: "You want me to...", "Should I...", "...?"
_ASKS = re.compile(
    r"\b(want me to|like me to|wish me to|asking me to|should i|shall i|may i|can i|"
    r"is this correct|is that correct|is that right|correct\?|right\?|confirm)\b|\?\s*$",
    _I,
)
_NEGATED_ASK = re.compile(r"\b(don't|do not|didn't|not) (want|like|wish) me to\b", _I)
_NOT_REQUEST = re.compile(
    r"\bnot (a |about )?(driving|drive)[- ]?(request|instruction|related)|\bno driving request"
    r"|\bnot related to driving\b|\bnot a request\b",
    _I,
)
_SENTENCE = re.compile(r"(?<=[.!?])\s+|\n+")


@dataclass(frozen=True, slots=True)
class ConfirmationReading:
    """What an LLM-1 reply means.

    Attributes:
        command: the one action it names, or ``None``.
        not_a_request: the model said the line is not a driving request.
        problem: why the reply was rejected (``None`` when it was read).
    """

    command: Command | None
    not_a_request: bool = False
    problem: str | None = None

    @property
    def ok(self) -> bool:
        """The reply was read: an action, or "not a driving request"."""
        return self.problem is None


def actions_named(text: str) -> set[Command]:
    """The commands whose action words occur in ``text``."""
    return {c for c, pattern in _ACTION_WORDS.items() if pattern.search(text)}


def read_confirmation(reply: str) -> ConfirmationReading:
    """Read an LLM-1 reply (see the module docstring).

    The question that names an action is the confirmation; the other sentences are
    chatter and are dropped, unless they name another action (a second option) or the
    question asks for two actions, which makes the reply ambiguous.
    """
    t = unwrap(reply)
    if not t:
        return ConfirmationReading(None, problem="empty reply")
    sentences = [s.strip() for s in _SENTENCE.split(t) if s.strip()]
    named = actions_named(t)
    if _NOT_REQUEST.search(t) and not any(_ASKS.search(s) for s in sentences if actions_named(s)):
        return ConfirmationReading(None, not_a_request=True)
    if len(named) > 1:
        names = ", ".join(sorted(c.label for c in named))
        return ConfirmationReading(None, problem=f"names more than one action ({names})")
    if not named:
        return ConfirmationReading(None, problem="names none of the three actions")
    command = next(iter(named))
    questions = [s for s in sentences if actions_named(s) and _ASKS.search(s)]
    if not questions:
        instruction_only = len(sentences) == 1 and len(sentences[0].split()) <= 6
        if not instruction_only:  # a bare "Drive more carefully." is an instruction
            return ConfirmationReading(None, problem="is not a confirmation question")
    if any(_NEGATED_ASK.search(s) for s in questions):
        return ConfirmationReading(None, problem="negates the action")
    return ConfirmationReading(command)


# --- LLM-2: the tag ---------------------------------------------------------------------

_EXPLAIN = re.compile(r"\[?\s*\bEXPLAIN\b\s*\]?", _I)
_NO_EXPLANATION = re.compile(r"\[?\s*\bNO[ _-]EXPLANATION([ _-]NEEDED)?\b\s*\]?", _I)


def read_decision_tag(reply: str) -> bool | None:
    """``True`` for ``[EXPLAIN]``, ``False`` for ``[NO EXPLANATION NEEDED]``, ``None`` when
    the reply holds both tags or neither (wrappers and brackets are tolerated)."""
    t = unwrap(reply)
    no = bool(_NO_EXPLANATION.search(t))
    yes = bool(_EXPLAIN.search(_NO_EXPLANATION.sub(" ", t)))
    if yes == no:
        return None
    return yes


# --- LLM-3: the passenger's text ----------------------------------------------------------

_LINK = re.compile(r"\[([^\]]+)\]\([^)]*\)")
_TAGS = re.compile(r"<[^>]{1,40}>")


def _plain(ch: str) -> bool:
    """Letters, digits, punctuation and spaces; no emoji, pictographs or control codes."""
    cat = unicodedata.category(ch)
    if cat.startswith(("L", "N", "P", "Z")):
        return ch.isascii() or cat.startswith(("L", "N")) or ch in "\u2013\u2014\u00b0"
    return ch in "/%+-" or (cat == "Sm" and ch.isascii())


def passenger_text(reply: str) -> str:
    """An explanation as the passenger may see it: plain text (no reasoning, fences, JSON,
    markup, tags or emoji), at most :data:`MAX_SENTENCES` sentences and
    :data:`MAX_PASSENGER_CHARS` characters, cut at a sentence end.

    Returns an empty string when nothing is left or the first sentence alone is longer
    than the limit.
    """
    t = _TAGS.sub(" ", _LINK.sub(r"\1", unwrap(reply)))
    t = "".join(ch if _plain(ch) else " " for ch in t)
    t = re.sub(r"\s+", " ", t).strip(" -:;,")
    t = re.sub(r"\s+([.,!?;:])", r"\1", t)
    sentences = [s for s in re.split(r"(?<=[.!?])\s+", t) if s]
    kept: list[str] = []
    for s in sentences[:MAX_SENTENCES]:
        if len(" ".join([*kept, s])) > MAX_PASSENGER_CHARS:
            break
        kept.append(s)
    out = " ".join(kept).strip()
    if out and out[-1] not in ".!?":
        out += "."
    return out
