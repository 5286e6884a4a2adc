"""LLM-1 shared pieces: the confirmation template, its parser, yes/no answers, results.

The paper's template is ``You want me to [action], is this correct?`` with the action
one of ``drive faster`` (fast, 0), ``drive more carefully`` (comfort, 1), ``stop`` (2).
"""

from __future__ import annotations

import re
from abc import ABC, abstractmethod
from dataclasses import dataclass

from explaindrive.commands import Command

ACTION_PHRASES: dict[Command, str] = {
    Command.FAST: "drive faster",
    Command.COMFORT: "drive more carefully",
    Command.STOP: "stop",
}
CONFIRMATION_TEMPLATE = "You want me to {action}, is this correct?"
REPHRASE_MESSAGE = (
    "Sorry, I can only change how I drive: faster, more carefully, or stop. "
    "Could you rephrase your request?"
)
WHY_MESSAGE = "Let me explain what I'm doing."
"""The reply to a question about the car's behaviour (reading ``why``)."""

_CONFIRMATION_RE = re.compile(
    r"You want me to (drive faster|drive more carefully|stop), is this correct\?"
)
_PHRASE_TO_COMMAND = {phrase: cmd for cmd, phrase in ACTION_PHRASES.items()}


@dataclass(frozen=True, slots=True)
class IntentResult:
    """Outcome of interpreting one passenger request.

    Attributes:
        intent: the command, or ``None`` when the request is not about driving style.
        confirmation: the template question for an intent, else a request to rephrase.
        backend: name of the backend that produced the answer (``embedded``/``openai``).
        fallback: ``True`` when the configured backend failed and ``embedded`` answered.
        latency_s: wall time of the call [s].
        scores: class probabilities when the backend exposes them (embedded), else empty.
        error: why the configured backend was bypassed, when ``fallback`` is ``True``.
        stop_lane: ``True`` when the embedded STOP check answered before any remote
            model was asked (a STOP is never left waiting on an endpoint).
        rule: with a remote model, the rule of :mod:`~explaindrive.language.intent.agreement`
            that chose between its reading and the embedded one; else ``None``.
        overruled: the remote model's reply was read but the embedded reading stood
            against it (rules ``local-sure-none`` and ``local-sure``).
        raw_reply: the remote model's reply as it came, for the ride log only (the
            passenger sees ``confirmation``).
        readings: when a remote reply was read, the two readings the agreement policy
            chose between: ``(embedded reading, its probability, remote reading)``, a
            reading ``None`` meaning "not a driving request"; else ``None``.
        reading: what the embedded model made of the line: a command's label, ``why`` (a
            question about the car's behaviour), ``yes`` / ``no`` (an answer to a
            confirmation) or ``none``; ``None`` when no embedded reading was made.
        ask: a command the car asks about without having read it (STOP, most probable but
            short of its threshold): ``intent`` is ``None``, ``confirmation`` asks, and the
            passenger's yes gives the command.
    """

    intent: Command | None
    confirmation: str | None
    backend: str
    fallback: bool
    latency_s: float
    scores: dict[str, float]
    error: str | None = None
    stop_lane: bool = False
    rule: str | None = None
    overruled: bool = False
    raw_reply: str | None = None
    readings: tuple[Command | None, float, Command | None] | None = None
    reading: str | None = None
    ask: Command | None = None

    def to_json(self) -> dict[str, object]:
        """The CLI's JSON shape."""
        return {
            "intent": self.intent.label if self.intent is not None else None,
            "confirmation": self.confirmation,
            "backend": self.backend,
            "fallback": self.fallback,
            "stop_lane": self.stop_lane,
            "rule": self.rule,
            "overruled": self.overruled,
            "reading": self.reading,
            "ask": self.ask.label if self.ask is not None else None,
        }


class IntentInterpreter(ABC):
    """LLM-1: maps a passenger request to a command and a confirmation question."""

    name: str = "abstract"

    @abstractmethod
    def interpret(self, text: str) -> IntentResult:
        """Interpret one passenger request (never raises on odd text)."""


def format_confirmation(command: Command) -> str:
    """The paper's confirmation question for ``command``."""
    return CONFIRMATION_TEMPLATE.format(action=ACTION_PHRASES[command])


def reply_to(command: Command | None, reading: str | None, ask: Command | None = None) -> str:
    """What the car says to a line: the confirmation question for a command (or for the
    command it asks about), a promise to explain for a question about its behaviour, else a
    request to rephrase."""
    asked = command if command is not None else ask
    if asked is not None:
        return format_confirmation(asked)
    return WHY_MESSAGE if reading == "why" else REPHRASE_MESSAGE


def parse_confirmation(text: str) -> Command | None:
    """The command of a reply that follows the template exactly, else ``None``.

    Surrounding white space and one pair of surrounding quotes are tolerated; any
    other text (options, explanations, a second sentence) makes the reply invalid.
    """
    reply = text.strip()
    if len(reply) >= 2 and reply[0] == reply[-1] and reply[0] in "\"'":
        reply = reply[1:-1].strip()
    match = _CONFIRMATION_RE.fullmatch(reply)
    return _PHRASE_TO_COMMAND[match.group(1)] if match else None


def is_template_compliant(text: str | None) -> bool:
    """Whether ``text`` is exactly a template confirmation question."""
    return text is not None and parse_confirmation(text) is not None
