"""OpenAI-compatible backend (OpenAI, Ollama, vLLM, llama.cpp) with the paper's prompts.

Every reply is read by :mod:`~explaindrive.language.backends.replies` (tolerant of wrappers,
strict in meaning) and held to the state: LLM-1's reading is weighed against the
embedded one (:mod:`~explaindrive.language.intent.agreement`), an LLM-2 ``[EXPLAIN]`` the state
does not bear out is vetoed, and LLM-3's text is checked against the state
(:mod:`~explaindrive.language.explanation.grounding`). A reply that cannot be read or is untrue, an
HTTP error or a call past its total deadline falls back to the embedded module and the
result says so (``fallback=True``, ``error=...``). The raw reply is kept in
``raw_reply`` for the ride log; the passenger sees only the checked, cleaned result.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import time
from typing import Any, TypeVar

from explaindrive.commands import COMMAND_LABELS, Command
from explaindrive.language.backends import deadline
from explaindrive.language.backends.deadline import DeadlineExceededError
from explaindrive.language.backends.embedded import (
    EmbeddedIntentInterpreter,
    RuleDecider,
    TemplateExplainer,
)
from explaindrive.language.backends.prompts import (
    DECISION_GRAMMAR,
    DECISION_PROMPT,
    EXPLAIN_PROMPT,
    INTENT_GRAMMAR,
    INTENT_PROMPT,
    situation_message,
)
from explaindrive.language.backends.replies import (
    passenger_text,
    read_confirmation,
    read_decision_tag,
)
from explaindrive.language.config import OpenAIConfig
from explaindrive.language.explanation.decision import (
    EXPLAIN_TAG,
    NO_EXPLANATION_TAG,
    Decision,
    ExplanationDecider,
    Factor,
    most_critical_factor,
    rule_decision,
)
from explaindrive.language.explanation.explainer import Explainer, Explanation
from explaindrive.language.explanation.grounding import reply_problems
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.language.intent.agreement import reconcile
from explaindrive.language.intent.interpreter import IntentInterpreter, IntentResult, reply_to
from explaindrive.language.intent.model import ANSWERS
from explaindrive.redact import redact

log = logging.getLogger(__name__)

NAME = "openai"


class BackendReplyError(RuntimeError):
    """The endpoint answered, but not in the required format."""


class ChatClient:
    """Thin wrapper over the official ``openai`` SDK's chat completions."""

    def __init__(self, config: OpenAIConfig) -> None:
        """Args: config: endpoint, model, timeout and retries."""
        from openai import OpenAI

        self.config = config
        # the key sent to the endpoint, masked in any text that comes back
        self.secret = config.api_key or os.environ.get(config.api_key_env)
        self._client = OpenAI(
            api_key=self.secret or "not-needed",
            base_url=config.base_url or os.environ.get(config.base_url_env) or None,
            timeout=config.timeout_s,
            max_retries=0,  # retried in complete(), within the call's deadline
            http_client=deadline.http_client(config.timeout_s),
        )

    def complete(
        self, system: str, user: str, temperature: float, grammar: str | None = None
    ) -> str:
        """One chat completion within ``config.timeout_s`` in total; returns the reply text.
        ``grammar`` (GBNF) is sent when ``config.grammar`` is on.

        The deadline covers connecting, sending, reading and the retries
        (``config.max_retries``, for connection errors, HTTP 429 and 5xx).

        Raises:
            DeadlineExceededError: when no complete answer came within the deadline.
            BackendReplyError: on an empty reply.
            openai.OpenAIError: on other HTTP errors.
        """
        import openai

        end = time.monotonic() + self.config.timeout_s
        for attempt in range(self.config.max_retries + 1):
            try:
                with deadline.until(end):
                    resp = self._create(system, user, temperature, grammar)
                break
            except openai.APITimeoutError as exc:
                raise DeadlineExceededError(
                    f"no answer within the {self.config.timeout_s:g} s deadline"
                ) from exc
            except (openai.APIConnectionError, openai.InternalServerError, openai.RateLimitError):
                if attempt == self.config.max_retries or time.monotonic() >= end:
                    raise
        return self._reply_text(resp)

    def _create(self, system: str, user: str, temperature: float, grammar: str | None) -> Any:
        extra = {"grammar": grammar} if grammar is not None and self.config.grammar else None
        return self._client.chat.completions.create(
            model=self.config.model,
            messages=[{"role": "system", "content": system}, {"role": "user", "content": user}],
            temperature=temperature,
            max_tokens=self.config.max_tokens,
            extra_body=extra,
        )

    def _reply_text(self, resp: Any) -> str:
        if not resp.choices or resp.choices[0].message.content is None:
            raise BackendReplyError("empty reply")
        return redact(str(resp.choices[0].message.content), [self.secret])


def _err(exc: Exception, client: ChatClient) -> str:
    """One line for a failed call, secrets masked (the endpoint may echo the key)."""
    return redact(f"{type(exc).__name__}: {exc}", [client.secret])[:300]


_R = TypeVar("_R", IntentResult, Decision, Explanation)


def _as_fallback(result: _R, t0: float, error: str, raw: str | None = None) -> _R:
    """The embedded module's ``result``, marked as a fallback for ``error``, timed from
    ``t0``, with the remote reply ``raw`` (when one came) kept for the log."""
    return dataclasses.replace(
        result, fallback=True, latency_s=time.perf_counter() - t0, error=error, raw_reply=raw
    )


class OpenAIIntentInterpreter(IntentInterpreter):
    """LLM-1 through the endpoint, weighed against the embedded interpreter."""

    name = NAME

    def __init__(self, client: ChatClient, fallback: EmbeddedIntentInterpreter) -> None:
        """Args: client: the chat client; fallback: the embedded interpreter."""
        self.client = client
        self.fallback = fallback

    def load(self) -> None:
        """Load the fallback's sentence encoder now, so that the first failed request is
        answered without paying the model load."""
        self.fallback.load()

    def interpret(self, text: str) -> IntentResult:
        """Read the request offline for STOP first, then ask the endpoint.

        The embedded interpreter reads every request first (tens of milliseconds). A STOP
        found there is returned at once (``stop_lane=True``) without asking the endpoint,
        so a STOP never waits on a remote model; nor is a yes or no to a confirmation
        question (``reading`` ``yes`` / ``no``) sent. Otherwise the endpoint's reply is read
        (:func:`~explaindrive.language.backends.replies.read_confirmation`) and the two readings
        are reconciled (:func:`~explaindrive.language.intent.agreement.reconcile`). On any
        failure, the deadline and an unreadable reply included, the embedded reading
        stands in (``fallback=True``). The confirmation is always the template of the
        command that counts, never the model's text; when no command counts and the
        embedded reader asked whether to stop, the car still asks.
        """
        t0 = time.perf_counter()
        local = self.fallback.interpret(text)
        if local.intent is Command.STOP or local.reading in ANSWERS or not text.strip():
            stop = local.intent is Command.STOP
            return dataclasses.replace(
                local,
                stop_lane=stop,
                rule="stop-local" if stop else None,
                latency_s=time.perf_counter() - t0,
            )
        raw: str | None = None
        try:
            raw = self.client.complete(
                INTENT_PROMPT, text, self.client.config.intent_temperature, INTENT_GRAMMAR
            )
            reading = read_confirmation(raw)
            if not reading.ok:
                raise BackendReplyError(f"reply not read: {reading.problem}: {raw[:120]!r}")
        except Exception as exc:  # any endpoint failure: answer offline instead
            error = _err(exc, self.client)
            log.warning("openai intent failed, using embedded: %s", error)
            return _as_fallback(local, t0, error, raw)
        return self._settle(text, local, reading.command, raw, t0)

    def _settle(
        self, text: str, local: IntentResult, remote: Command | None, raw: str, t0: float
    ) -> IntentResult:
        """The result once the embedded reading ``local`` and the remote reading ``remote``
        (from the reply ``raw``) are reconciled."""
        label = local.intent.label if local.intent is not None else "none"
        local_p = local.scores.get(label, 0.0)
        verdict = reconcile(
            local.intent, local_p, remote, NAME, self.client.config.trust_embedded_from
        )
        if verdict.source != "both":
            log.info("intent readings differ for %r: %s (%s)", text, verdict.intent, verdict.rule)
        ask = local.ask if verdict.intent is None else None
        return IntentResult(
            verdict.intent,
            reply_to(verdict.intent, _reading(verdict.intent, local.reading), ask),
            NAME,
            False,
            time.perf_counter() - t0,
            local.scores,
            rule=verdict.rule,
            overruled=verdict.source == "embedded",
            raw_reply=raw,
            readings=(local.intent, local_p, remote),
            reading=_reading(verdict.intent, local.reading),
            ask=ask,
        )


def _reading(intent: Command | None, local: str | None) -> str | None:
    """The line's reading once the command is settled: the command's label, else the
    embedded reading when it was no command (``why``, an answer), else ``none``."""
    if intent is not None:
        return intent.label
    return local if local not in COMMAND_LABELS else "none"


class OpenAIDecider(ExplanationDecider):
    """LLM-2 through the endpoint, held to the state by the rule engine."""

    name = NAME

    def __init__(self, client: ChatClient, fallback: RuleDecider) -> None:
        """Args: client: the chat client; fallback: the rule engine."""
        self.client = client
        self.fallback = fallback

    def decide(self, record: StateRecord) -> Decision:
        """Ask for one tag; an unreadable reply falls back to the rule engine.

        ``[NO EXPLANATION NEEDED]`` is followed. ``[EXPLAIN]`` is followed only when the
        rule engine finds a conflict with the request and a safety factor to name (the
        factor is the rule engine's); otherwise it is vetoed (``vetoed=True``, logged), so
        an over-eager model never explains more than the rule engine would.
        """
        t0 = time.perf_counter()
        cutoff = self.fallback.config.cutoff_m
        raw: str | None = None
        try:
            raw = self.client.complete(
                DECISION_PROMPT,
                situation_message(record, cutoff),
                self.client.config.decision_temperature,
                DECISION_GRAMMAR,
            )
            explain = read_decision_tag(raw)
            if explain is None:
                raise BackendReplyError(f"reply is not one tag: {raw[:120]!r}")
        except Exception as exc:
            error = _err(exc, self.client)
            log.warning("openai decision failed, using rules: %s", error)
            return _as_fallback(self.fallback.decide(record), t0, error, raw)
        rules = rule_decision(record, cutoff)
        vetoed = explain and not rules.explain
        reason = f"endpoint replied {EXPLAIN_TAG if explain else NO_EXPLANATION_TAG}"
        if vetoed:
            reason = f"vetoed {EXPLAIN_TAG}: {rules.reason}"
            log.info("%s", reason)
        return Decision(
            explain and rules.explain,
            rules.factor if explain and rules.explain else None,
            rules.conflict,
            reason,
            NAME,
            latency_s=time.perf_counter() - t0,
            vetoed=vetoed,
            raw_reply=raw,
        )


class OpenAIExplainer(Explainer):
    """LLM-3 through the endpoint (temperature 0.2); untrue replies fall back."""

    name = NAME

    def __init__(self, client: ChatClient, fallback: TemplateExplainer) -> None:
        """Args: client: the chat client; fallback: the template explainer."""
        self.client = client
        self.fallback = fallback

    def explain(self, record: StateRecord, factor: Factor | None) -> Explanation:
        """Ask for an explanation, clean it and check it against the state before use.

        The reply is reduced to plain text for the passenger
        (:func:`~explaindrive.language.backends.replies.passenger_text`) and must then pass
        :func:`~explaindrive.language.explanation.grounding.reply_problems` (it names the factor, or
        with none given a factor present in the state, and nothing absent; the light's
        true colour, distances and speeds near the state's, wording true of the action);
        otherwise the template explanation stands in and ``error`` says why. With no
        factor in the state the endpoint is not asked. Never raises.
        """
        t0 = time.perf_counter()
        cutoff = self.fallback.config.cutoff_m
        factor = factor or most_critical_factor(record, cutoff)
        if factor is None:
            return _as_fallback(
                self.fallback.explain(record, None), t0, "no safety factor in the state"
            )
        raw: str | None = None
        try:
            raw = self.client.complete(
                EXPLAIN_PROMPT,
                situation_message(record, cutoff),
                self.client.config.explain_temperature,
            )
            text = passenger_text(raw)
            problems = reply_problems(text, record, factor, cutoff)
            if problems:
                error = f"explanation rejected: {'; '.join(problems)}"
                log.info("openai explanation vetoed, using templates: %s", error)
                vetoed = _as_fallback(self.fallback.explain(record, factor), t0, error, raw)
                return dataclasses.replace(vetoed, vetoed=True)
            return Explanation(
                text, factor, NAME, latency_s=time.perf_counter() - t0, raw_reply=raw
            )
        except Exception as exc:
            error = _err(exc, self.client)
            log.warning("openai explanation failed, using templates: %s", error)
            return _as_fallback(self.fallback.explain(record, factor), t0, error, raw)
