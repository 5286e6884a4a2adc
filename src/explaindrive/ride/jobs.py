"""The ride's language jobs, one typed record each, and the typed results of their tasks.

A job travels with its task through the language lane (:mod:`explaindrive.ride.lane`);
when the task comes back, the ride hands its result to the job's owner by the job's type:
an :class:`Interpretation` for an :class:`InterpretJob`, a
:class:`~explaindrive.language.explanation.decision.Decision` for a :class:`DecideJob`, an
:class:`~explaindrive.language.explanation.explainer.Explanation` for an
:class:`ExplainJob`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from explaindrive.language.explanation.decision import Decision
from explaindrive.language.explanation.explainer import Explanation
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.interpreter import IntentResult
from explaindrive.ride.records import PassengerRequest


@dataclass(frozen=True)
class InterpretJob:
    """Transcribe (a spoken line) and interpret a passenger request (LLM-1)."""

    request: PassengerRequest


@dataclass(frozen=True)
class DecideJob:
    """Decide whether the step ``step`` needs an explanation (LLM-2)."""

    record: StateRecord
    step: int


@dataclass(frozen=True)
class ExplainJob:
    """Explain the step ``step`` (LLM-3); ``question`` is the id of the passenger's "why?"
    request it answers, ``None`` for an explanation LLM-2 decided on."""

    step: int
    question: int | None = None


LanguageJob = InterpretJob | DecideJob | ExplainJob
"""Any of the ride's language jobs."""


class Interpretation(NamedTuple):
    """What the interpretation worker returns for one request."""

    text: str
    """The typed text, or the transcript of the recording."""
    result: IntentResult | None
    """LLM-1's reading; ``None`` when there was no text to read."""
    transcribe_s: float
    """[s] wall time of the transcription (0 for a typed line)."""
    problem: str | None
    """Why there is no text (an unreadable recording, an empty request), else ``None``."""


LanguageResult = Interpretation | Decision | Explanation
"""What a language job's task returns (LLM-1, LLM-2, LLM-3)."""
