"""One place that assembles the language layer for a backend of the registry
(:mod:`explaindrive.language.backends`)."""

from __future__ import annotations

from dataclasses import dataclass

from explaindrive.language.backends import check_backend, get_backend
from explaindrive.language.config import LanguageConfig
from explaindrive.language.explanation.decision import ExplanationDecider
from explaindrive.language.explanation.explainer import Explainer
from explaindrive.language.explanation.summary import SUMMARY_CUTOFF_M
from explaindrive.language.intent.interpreter import IntentInterpreter
from explaindrive.language.speech.transcriber import SpeechToText, Transcriber


@dataclass(frozen=True)
class LanguageStack:
    """The four modules the ride loop calls.

    Attributes:
        remote_deadline_s: the total deadline of one call to a remote model [s], after
            which the embedded module answers; ``None`` when nothing remote is called.
        cutoff_m: objects farther than this are left out of decisions and explanations [m].
    """

    backend: str
    interpreter: IntentInterpreter
    decider: ExplanationDecider
    explainer: Explainer
    transcriber: SpeechToText
    remote_deadline_s: float | None = None
    cutoff_m: float = SUMMARY_CUTOFF_M

    def load(self, speech: bool = False) -> LanguageStack:
        """Load the interpreter's model now (and Whisper's with ``speech``); returns self.

        A ride calls this before it starts so that no request pays the load time.
        """
        load = getattr(self.interpreter, "load", None)
        if callable(load):
            load()
        if speech:
            self.transcriber.load()
        return self


def make_language_stack(
    backend: str | None = None, config: LanguageConfig | None = None
) -> LanguageStack:
    """Build interpreter, decider, explainer and transcriber for ``backend``.

    Models load lazily (on first use); call ``stack.interpreter.load()`` /
    ``stack.transcriber.load()`` to pay that cost up front.

    Args:
        backend: a registered backend's name (``embedded``, ``openai``...); ``None`` =
            ``config.backend``.
        config: the layer's configuration; ``None`` = defaults.

    Raises:
        ValueError: for an unknown backend name.
    """
    cfg = config or LanguageConfig()
    name = check_backend(backend or cfg.backend)
    modules = get_backend(name).build(cfg)
    return LanguageStack(
        name,
        modules.interpreter,
        modules.decider,
        modules.explainer,
        Transcriber(cfg.speech),
        modules.remote_deadline_s,
        cfg.embedded.cutoff_m,
    )
