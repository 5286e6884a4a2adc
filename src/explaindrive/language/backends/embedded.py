"""The offline, deterministic backend: embedding classifier, rule engine, templates."""

from __future__ import annotations

import logging
import time
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from explaindrive.commands import Command
from explaindrive.language.cascade import LARGE, SMALL, CascadeRule
from explaindrive.language.config import EmbeddedConfig
from explaindrive.language.datasets import INTENT_LABELS
from explaindrive.language.decision import Decision, ExplanationDecider, Factor, rule_decision
from explaindrive.language.encoders import EncoderName
from explaindrive.language.explanation import Explainer, Explanation, template_explanation
from explaindrive.language.features import SentenceEncoder, features
from explaindrive.language.intent import (
    REPHRASE_MESSAGE,
    IntentInterpreter,
    IntentResult,
    format_confirmation,
)
from explaindrive.language.intent_classifier import IntentClassifier
from explaindrive.language.summary import StateRecord

log = logging.getLogger(__name__)

NAME = "embedded"


class IntentStage:
    """One sentence encoder with the classifier shipped for it."""

    def __init__(self, name: EncoderName, config: EmbeddedConfig) -> None:
        """Args: name: the encoder; config: backend options (threads, paths)."""
        self.encoder = SentenceEncoder(config.embedding_model_dir, config.encoder_threads, name)
        self.classifier = IntentClassifier.load(config.classifier_path, name)

    def proba(self, text: str) -> NDArray[np.float64]:
        """Class probabilities of one request."""
        return self.classifier.proba(features(self.encoder, [text], self.classifier.spec))[0]


class EmbeddedIntentInterpreter(IntentInterpreter):
    """LLM-1 offline: sentence-encoder features and a shipped classifier, one encoder or
    the cascade of :mod:`explaindrive.language.cascade` (MiniLM, then mpnet for the
    requests MiniLM is least sure of)."""

    name = NAME

    def __init__(self, config: EmbeddedConfig | None = None) -> None:
        """Args: config: backend options (``intent_model`` picks the model)."""
        self.config = config or EmbeddedConfig()
        model = self.config.intent_model
        names: tuple[EncoderName, ...] = (SMALL, LARGE) if model == "cascade" else (model,)
        self.stages = [IntentStage(n, self.config) for n in names]
        self.rule: CascadeRule | None = None
        if model == "cascade":
            rule = CascadeRule.load()
            if self.config.escalation_margin is not None:
                rule = replace(rule, escalation_margin=self.config.escalation_margin)
            self.rule = rule

    @property
    def encoder(self) -> SentenceEncoder:
        """The first (for the cascade: the small) encoder."""
        return self.stages[0].encoder

    @property
    def classifier(self) -> IntentClassifier:
        """The first (for the cascade: the small) encoder's classifier."""
        return self.stages[0].classifier

    def load(self) -> None:
        """Load the sentence encoders now rather than on the first request."""
        for stage in self.stages:
            stage.encoder.load()

    def interpret(self, text: str) -> IntentResult:
        """Classify ``text``; an empty or off-topic request gets a request to rephrase."""
        t0 = time.perf_counter()
        if not text or not text.strip():
            return IntentResult(None, REPHRASE_MESSAGE, NAME, False, time.perf_counter() - t0, {})
        stage = self.stages[0]
        p = stage.proba(text)
        if self.rule is not None and self.rule.escalate(p):
            stage = self.stages[1]
            p = stage.proba(text)
        label = stage.classifier.decide(p, self.config.stop_threshold, self.config.none_margin)
        scores = {name: round(float(v), 4) for name, v in zip(INTENT_LABELS, p, strict=True)}
        intent = None if label == "none" else Command.parse(label)
        confirmation = format_confirmation(intent) if intent is not None else REPHRASE_MESSAGE
        latency = time.perf_counter() - t0
        log.debug("embedded intent %s for %r by %s (%s)", label, text, stage.encoder.name, scores)
        return IntentResult(
            intent, confirmation, NAME, False, latency, scores, model=stage.encoder.name
        )


class RuleDecider(ExplanationDecider):
    """LLM-2 offline: the grounded rule engine of :mod:`explaindrive.language.decision`."""

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

        Raises:
            ValueError: if no factor is given and the state holds no safety reason.
        """
        t0 = time.perf_counter()
        if factor is None:
            factor = rule_decision(record, self.config.cutoff_m).factor
            if factor is None:
                raise ValueError("nothing to explain: no safety factor in the state")
        text = template_explanation(record, factor, self.config.cutoff_m)
        return Explanation(text, factor, NAME, latency_s=time.perf_counter() - t0)
