"""The language modules a ride uses, behind one small record."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from explaindrive.language.decision import ExplanationDecider
from explaindrive.language.explanation import Explainer
from explaindrive.language.intent import IntentInterpreter


@dataclass
class LanguageStack:
    """LLM-1, LLM-2, LLM-3 and speech-to-text for a ride.

    Attributes:
        interpreter: LLM-1 (command interpretation with confirmation question).
        decider: LLM-2 (explain or not).
        explainer: LLM-3 (the explanation).
        transcribe: speech-to-text of an audio file; returns "" for no speech.
    """

    interpreter: IntentInterpreter
    decider: ExplanationDecider
    explainer: Explainer
    transcribe: Callable[[Path], str]
