"""One place that assembles the language layer for a backend."""

from __future__ import annotations

from dataclasses import dataclass

from explaindrive.language.backends import check_backend
from explaindrive.language.backends.embedded import (
    EmbeddedIntentInterpreter,
    RuleDecider,
    TemplateExplainer,
)
from explaindrive.language.config import LanguageConfig
from explaindrive.language.decision import ExplanationDecider
from explaindrive.language.explanation import Explainer
from explaindrive.language.intent import IntentInterpreter
from explaindrive.language.speech import SpeechToText, Transcriber


@dataclass(frozen=True)
class LanguageStack:
    """The four modules the ride loop calls.

    Attributes:
        remote_deadline_s: the total deadline of one call to a remote model [s], after
            which the embedded module answers; ``None`` when nothing remote is called.
    """

    backend: str
    interpreter: IntentInterpreter
    decider: ExplanationDecider
    explainer: Explainer
    transcriber: SpeechToText
    remote_deadline_s: float | None = None

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
        backend: ``embedded`` or ``openai``; ``None`` = ``config.backend``.
        config: the layer's configuration; ``None`` = defaults.

    Raises:
        ValueError: for an unknown backend name.
    """
    cfg = config or LanguageConfig()
    name = check_backend(backend or cfg.backend)
    interpreter: IntentInterpreter = EmbeddedIntentInterpreter(cfg.embedded)
    decider: ExplanationDecider = RuleDecider(cfg.embedded)
    explainer: Explainer = TemplateExplainer(cfg.embedded)
    if name == "openai":
        from explaindrive.language.backends.openai import (
            ChatClient,
            OpenAIDecider,
            OpenAIExplainer,
            OpenAIIntentInterpreter,
        )

        client = ChatClient(cfg.openai)
        assert isinstance(interpreter, EmbeddedIntentInterpreter)
        assert isinstance(decider, RuleDecider) and isinstance(explainer, TemplateExplainer)
        interpreter = OpenAIIntentInterpreter(client, interpreter)
        decider = OpenAIDecider(client, decider)
        explainer = OpenAIExplainer(client, explainer)
    remote = cfg.openai.timeout_s if name == "openai" else None
    return LanguageStack(name, interpreter, decider, explainer, Transcriber(cfg.speech), remote)
