"""The offline, deterministic backend: the fine-tuned intent model, rule engine, templates."""

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
from explaindrive.language.intent.interpreter import (
    REPHRASE_MESSAGE,
    IntentInterpreter,
    IntentResult,
    reply_to,
)
from explaindrive.language.intent.model import Reading
from explaindrive.language.intent.reader import LineReader

log = logging.getLogger(__name__)

NAME = "embedded"


class EmbeddedIntentInterpreter(IntentInterpreter):
    """LLM-1 offline: the fine-tuned sentence encoder and its reading head
    (:mod:`explaindrive.language.intent.model`)."""

    name = NAME

    def __init__(self, config: EmbeddedConfig | None = None) -> None:
        """Args: config: backend options (the model, its thresholds, the encoder runtime).

        Raises:
            FileNotFoundError, ValueError: for a missing or invalid model file.
        """
        self.config = config or EmbeddedConfig()
        self.reader = LineReader(
            self.config.model_path,
            self.config.embedding_model_dir,
            self.config.encoder_threads,
            self.config.encoder_runtime,
            self.config.command_threshold,
            self.config.stop_threshold,
            self.config.stop_path,
            self.config.ask_stop,
        )

    def load(self) -> None:
        """Build and load the fine-tuned encoder now rather than on the first request."""
        self.reader.load()

    def interpret(self, text: str) -> IntentResult:
        """Read ``text``; a line that asks for no command gets a request to rephrase.

        The result's ``reading`` says what the line is when it is not a command: ``why``
        (a question about the car's behaviour), ``yes`` / ``no`` (an answer), ``none``; its
        ``ask`` is STOP when the car asks whether to stop (STOP most probable but unsure).
        """
        t0 = time.perf_counter()
        if not text or not text.strip():
            return IntentResult(
                None, REPHRASE_MESSAGE, NAME, False, time.perf_counter() - t0, {}, reading="none"
            )
        (reading,) = self.reader.read([text])
        intent = Command.parse(reading.command) if reading.command is not None else None
        ask = Command.STOP if reading.ask_stop else None
        confirmation = reply_to(intent, reading.reading, ask)
        log.debug("embedded reading %s for %r (%s)", reading.reading, text, reading.scores())
        return IntentResult(
            intent,
            confirmation,
            NAME,
            False,
            time.perf_counter() - t0,
            command_scores(reading),
            reading=reading.reading,
            ask=ask,
        )


def command_scores(reading: Reading) -> dict[str, float]:
    """The probabilities of the three commands and of ``none``, every reading that asks for
    no command taken together (what the agreement with a remote model weighs)."""
    scores = {c.label: float(reading.p[c]) for c in Command}
    scores["none"] = max(0.0, 1.0 - sum(scores.values()))
    return {k: round(v, 4) for k, v in scores.items()}


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
