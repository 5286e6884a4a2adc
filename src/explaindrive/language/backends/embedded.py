"""The offline, deterministic backend: embedding classifier, rule engine, templates."""

from __future__ import annotations

import logging
import time

from explaindrive.commands import Command
from explaindrive.language.config import EmbeddedConfig
from explaindrive.language.explanation.decision import (
    Decision,
    ExplanationDecider,
    Factor,
    rule_decision,
)
from explaindrive.language.explanation.explainer import (
    Explainer,
    Explanation,
    neutral_explanation,
    template_explanation,
)
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.classifier import IntentClassifier
from explaindrive.language.intent.corrections import last_instruction
from explaindrive.language.intent.datasets import INTENT_LABELS
from explaindrive.language.intent.features import SentenceEncoder, features
from explaindrive.language.intent.interpreter import (
    REPHRASE_MESSAGE,
    IntentInterpreter,
    IntentResult,
    format_confirmation,
)
from explaindrive.language.intent.negation import stop_is_ruled_out

log = logging.getLogger(__name__)

NAME = "embedded"
_STOP = INTENT_LABELS.index("stop")


class EmbeddedIntentInterpreter(IntentInterpreter):
    """LLM-1 offline: sentence-encoder features + the shipped classifier."""

    name = NAME

    def __init__(
        self, config: EmbeddedConfig | None = None, encoder: SentenceEncoder | None = None
    ) -> None:
        """Args: config: backend options; encoder: share one loaded encoder between users."""
        self.config = config or EmbeddedConfig()
        self.encoder = encoder or SentenceEncoder(
            self.config.embedding_model_dir,
            self.config.encoder_threads,
            self.config.encoder_runtime,
        )
        self.classifier = IntentClassifier.load(self.config.classifier_path)

    def load(self) -> None:
        """Load the sentence encoder now rather than on the first request."""
        self.encoder.load()

    def interpret(self, text: str) -> IntentResult:
        """Classify ``text``; an empty or off-topic request gets a request to rephrase.

        A request that corrects itself is read by its last instruction: the part after
        its last repair marker (:func:`~explaindrive.language.intent.corrections.last_instruction`)
        decides whenever it asks for a command on its own. A line that mentions stopping
        only negated or in a complaint
        (:func:`~explaindrive.language.intent.negation.stop_is_ruled_out`) is not read as STOP.
        """
        t0 = time.perf_counter()
        if not text or not text.strip():
            return IntentResult(None, REPHRASE_MESSAGE, NAME, False, time.perf_counter() - t0, {})
        last = last_instruction(text)
        texts = [text] if last is None else [text, last]
        p = self.classifier.proba(features(self.encoder, texts, self.classifier.spec))
        for i, t in enumerate(texts):  # "don't stop here", "another red light": not STOP
            if stop_is_ruled_out(t):
                p[i, _STOP] = 0.0
                p[i] /= max(float(p[i].sum()), 1e-12)
        labels = [
            self.classifier.decide(row, self.config.stop_threshold, self.config.none_margin)
            for row in p
        ]
        row = 1 if last is not None and labels[1] != "none" else 0
        label = labels[row]
        scores = {name: round(float(v), 4) for name, v in zip(INTENT_LABELS, p[row], strict=True)}
        intent = None if label == "none" else Command.parse(label)
        confirmation = format_confirmation(intent) if intent is not None else REPHRASE_MESSAGE
        latency = time.perf_counter() - t0
        log.debug("embedded intent %s for %r (%s)", label, text, scores)
        return IntentResult(
            intent,
            confirmation,
            NAME,
            False,
            latency,
            scores,
            instruction=texts[row] if row == 1 else None,
        )


class RuleDecider(ExplanationDecider):
    """LLM-2 offline: the grounded rule engine of
    :mod:`explaindrive.language.explanation.decision`."""

    name = NAME

    def __init__(self, config: EmbeddedConfig | None = None) -> None:
        """Args: config: backend options (the distance cut-off)."""
        self.config = config or EmbeddedConfig()

    def decide(self, record: StateRecord) -> Decision:
        """Decide whether to explain ``record``'s action."""
        t0 = time.perf_counter()
        d = rule_decision(record, self.config.cutoff_m)
        return Decision(
            d.explain, d.factor, d.conflict, d.reason, NAME, latency_s=time.perf_counter() - t0
        )


class TemplateExplainer(Explainer):
    """LLM-3 offline: varied, grounded template sentences."""

    name = NAME

    def __init__(self, config: EmbeddedConfig | None = None) -> None:
        """Args: config: backend options (the distance cut-off)."""
        self.config = config or EmbeddedConfig()

    def explain(self, record: StateRecord, factor: Factor | None) -> Explanation:
        """Explain ``record``'s action by ``factor`` (by the rule engine's pick when ``None``).

        When the state holds no safety reason, or ``factor`` cannot explain the action,
        the explanation names no factor (:func:`neutral_explanation`). Never raises.
        """
        t0 = time.perf_counter()
        if factor is None:
            factor = rule_decision(record, self.config.cutoff_m).factor
        try:
            if factor is None:
                raise ValueError("no safety factor in the state")
            text = template_explanation(record, factor, self.config.cutoff_m)
        except ValueError as exc:
            log.info("no grounded explanation (%s); a neutral one is given", exc)
            text, factor = neutral_explanation(record), None
        return Explanation(text, factor, NAME, latency_s=time.perf_counter() - t0)
