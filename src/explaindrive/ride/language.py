"""The language modules a ride calls, behind one small record."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from explaindrive.language.config import LanguageConfig
from explaindrive.language.decision import ExplanationDecider
from explaindrive.language.explanation import Explainer
from explaindrive.language.intent import IntentInterpreter


@dataclass
class RideLanguage:
    """LLM-1, LLM-2, LLM-3 and speech-to-text for a ride.

    Attributes:
        interpreter: LLM-1 (command interpretation with confirmation question).
        decider: LLM-2 (explain or not).
        explainer: LLM-3 (the explanation).
        transcribe: speech-to-text of an audio file; raises
            :class:`explaindrive.language.speech.AudioError` for unusable audio.
    """

    interpreter: IntentInterpreter
    decider: ExplanationDecider
    explainer: Explainer
    transcribe: Callable[[Path], str]


def build_language(
    backend: str = "embedded", config: LanguageConfig | None = None, speech: bool = False
) -> RideLanguage:
    """The language layer for ``backend`` (``embedded`` or ``openai``), models loaded.

    Args:
        backend: ``embedded`` or ``openai``.
        config: the language layer's settings (defaults when omitted).
        speech: also load Whisper now (otherwise on the first spoken request).

    Raises:
        ValueError: for an unknown backend.
    """
    from explaindrive.language.stack import make_language_stack

    stack = make_language_stack(backend, config)
    load = getattr(stack.interpreter, "load", None)
    if callable(load):
        load()  # pay the embedding model's load before the ride starts
    if speech:
        stack.transcriber.load()

    def transcribe(path: Path) -> str:
        return stack.transcriber.transcribe(path).text

    return RideLanguage(stack.interpreter, stack.decider, stack.explainer, transcribe)
