"""OpenAI-compatible backend (OpenAI, Ollama, vLLM, llama.cpp) with the paper's prompts.

Every reply is validated (LLM-1 template, LLM-2 tag, LLM-3 checked against the state);
a malformed or untrue reply, an HTTP error or a call past its total deadline falls back
to the embedded module and the result says so (``fallback=True``, ``error=...``). The
embedded interpreter reads every request first and answers a STOP itself.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import time
from typing import Any, TypeVar

from explaindrive.commands import Command
from explaindrive.language.backends import deadline
from explaindrive.language.backends.deadline import DeadlineExceededError
from explaindrive.language.backends.embedded import (
    EmbeddedIntentInterpreter,
    RuleDecider,
    TemplateExplainer,
)
from explaindrive.language.config import OpenAIConfig
from explaindrive.language.decision import (
    Decision,
    ExplanationDecider,
    Factor,
    detect_conflict,
    most_critical_factor,
    parse_decision_tag,
)
from explaindrive.language.explanation import Explainer, Explanation
from explaindrive.language.grounding import reply_problems
from explaindrive.language.intent import IntentInterpreter, IntentResult, parse_confirmation
from explaindrive.language.summary import StateRecord, describe_action, environment_summary
from explaindrive.redact import redact

log = logging.getLogger(__name__)

NAME = "openai"

# The paper's prompts, verbatim (section 4).
INTENT_PROMPT = (
    "You are an autonomous taxi's AI assistant. Reformulate the passenger's request into a "
    "direct instruction about how the vehicle should drive. The instruction must correspond "
    "to one of the following driving styles: drive faster, drive more carefully, or stop. At "
    'the end, confirm the reformulation using the following format: "You want me to '
    '[action], is this correct?" Do not provide multiple options or add any extra text. Only '
    "output the direct confirmation question."
)
DECISION_PROMPT = """You are an AI reasoning module for an autonomous taxi. Your task is to output exactly ONE of:
- [EXPLAIN]
- [NO EXPLANATION NEEDED]

Principles to decide:

1) Return [EXPLAIN] only if the vehicle’s present action clearly conflicts
or delays the user’s request for a clear safety reason (e.g., decelerating
when asked for driving faster, or harsh acceleration or deceleration when
asked for a comfortable ride).

2) Return [NO EXPLANATION NEEDED] for behavior that is ordinary, supportive,
or neutral with respect to the request (e.g., maintaining speed when user
asked for comfort, smooth acceleration/braking).

3) Multiple reasons: If several safety reasons exist, internally consider
the most safety-critical one.
Output only the tag. Do not include any justification or text besides the
tag."""  # noqa: E501
EXPLAIN_PROMPT = """You are an AI assistant inside an autonomous taxi. Your job is to explain
to the passenger why the vehicle’s action seems to contradict their request.
When that happens, briefly explain the most safety-relevant nearby reason
for the vehicle’s behavior, using a friendly and reassuring tone. Keep
it concise."""

_REQUEST_TEXT = {"fast": "drive faster", "comfort": "drive more carefully", "stop": "stop"}


class BackendReplyError(RuntimeError):
    """The endpoint answered, but not in the required format."""


def situation_message(record: StateRecord, cutoff_m: float) -> str:
    """The user message of LLM-2/LLM-3: request, action and environment summary."""
    return (
        f"Passenger request: {_REQUEST_TEXT[record.request]}\n"
        f"Vehicle action: {describe_action(record.action)}\n"
        f"Environment: {environment_summary(record, cutoff_m)}"
    )


class ChatClient:
    """Thin wrapper over the official ``openai`` SDK's chat completions."""

    def __init__(self, config: OpenAIConfig) -> None:
        """Args: config: endpoint, model, timeout and retries."""
        from openai import OpenAI

        self.config = config
        # the key sent to the endpoint, masked in any text that comes back
        self.secret = config.api_key or os.environ.get("OPENAI_API_KEY")
        self._client = OpenAI(
            api_key=self.secret or "not-needed",
            base_url=config.base_url or os.environ.get("OPENAI_BASE_URL") or None,
            timeout=config.timeout_s,
            max_retries=0,  # retried in complete(), within the call's deadline
            http_client=deadline.http_client(config.timeout_s),
        )

    def complete(self, system: str, user: str, temperature: float) -> str:
        """One chat completion within ``config.timeout_s`` in total; returns the reply text.

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
                    resp = self._create(system, user, temperature)
                break
            except openai.APITimeoutError as exc:
                raise DeadlineExceededError(
                    f"no answer within the {self.config.timeout_s:g} s deadline"
                ) from exc
            except (openai.APIConnectionError, openai.InternalServerError, openai.RateLimitError):
                if attempt == self.config.max_retries or time.monotonic() >= end:
                    raise
        return self._reply_text(resp)

    def _create(self, system: str, user: str, temperature: float) -> Any:
        return self._client.chat.completions.create(
            model=self.config.model,
            messages=[{"role": "system", "content": system}, {"role": "user", "content": user}],
            temperature=temperature,
            max_tokens=self.config.max_tokens,
        )

    def _reply_text(self, resp: Any) -> str:
        if not resp.choices or resp.choices[0].message.content is None:
            raise BackendReplyError("empty reply")
        return redact(str(resp.choices[0].message.content), [self.secret])


def _err(exc: Exception, client: ChatClient) -> str:
    """One line for a failed call, secrets masked (the endpoint may echo the key)."""
    return redact(f"{type(exc).__name__}: {exc}", [client.secret])[:300]


_R = TypeVar("_R", IntentResult, Decision, Explanation)


def _as_fallback(result: _R, t0: float, error: str) -> _R:
    """The embedded module's ``result``, marked as a fallback for ``error``, timed from ``t0``."""
    return dataclasses.replace(
        result, fallback=True, latency_s=time.perf_counter() - t0, error=error
    )


class OpenAIIntentInterpreter(IntentInterpreter):
    """LLM-1 through the endpoint; falls back to the embedded interpreter."""

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
        so a STOP never waits on a remote model. Otherwise the endpoint's reply must be
        exactly the confirmation template; on any failure, the deadline included, the
        embedded reading stands in (``fallback=True``).
        """
        t0 = time.perf_counter()
        local = self.fallback.interpret(text)
        if local.intent is Command.STOP:
            return dataclasses.replace(local, stop_lane=True, latency_s=time.perf_counter() - t0)
        try:
            reply = self.client.complete(INTENT_PROMPT, text, self.client.config.intent_temperature)
            command = parse_confirmation(reply)
            if command is None:
                raise BackendReplyError(f"reply does not follow the template: {reply[:120]!r}")
            return IntentResult(
                command, reply.strip().strip("\"'"), NAME, False, time.perf_counter() - t0, {}
            )
        except Exception as exc:  # any endpoint failure: answer offline instead
            error = _err(exc, self.client)
            log.warning("openai intent failed, using embedded: %s", error)
            return _as_fallback(local, t0, error)


class OpenAIDecider(ExplanationDecider):
    """LLM-2 through the endpoint; the factor comes from the grounded ranking."""

    name = NAME

    def __init__(self, client: ChatClient, fallback: RuleDecider) -> None:
        """Args: client: the chat client; fallback: the rule engine."""
        self.client = client
        self.fallback = fallback

    def decide(self, record: StateRecord) -> Decision:
        """Ask for one tag; anything else falls back to the rule engine."""
        t0 = time.perf_counter()
        cutoff = self.fallback.config.cutoff_m
        try:
            reply = self.client.complete(
                DECISION_PROMPT,
                situation_message(record, cutoff),
                self.client.config.decision_temperature,
            )
            explain = parse_decision_tag(reply)
            if explain is None:
                raise BackendReplyError(f"reply is not one tag: {reply[:120]!r}")
            factor = most_critical_factor(record, cutoff) if explain else None
            return Decision(
                explain,
                factor,
                detect_conflict(record, cutoff),
                f"endpoint replied {reply.strip()}",
                NAME,
                latency_s=time.perf_counter() - t0,
            )
        except Exception as exc:
            error = _err(exc, self.client)
            log.warning("openai decision failed, using rules: %s", error)
            return _as_fallback(self.fallback.decide(record), t0, error)


class OpenAIExplainer(Explainer):
    """LLM-3 through the endpoint (temperature 0.2); ungrounded replies fall back."""

    name = NAME

    def __init__(self, client: ChatClient, fallback: TemplateExplainer) -> None:
        """Args: client: the chat client; fallback: the template explainer."""
        self.client = client
        self.fallback = fallback

    def explain(self, record: StateRecord, factor: Factor | None) -> Explanation:
        """Ask for an explanation and check it against the state before it is used.

        The reply must pass :func:`~explaindrive.language.grounding.reply_problems` (an
        explanation naming the factor, no absent factor or invented hazard, the light's
        true colour, distances and speeds near the state's, wording true of the action);
        otherwise the template explanation stands in and ``error`` says why.
        """
        t0 = time.perf_counter()
        cutoff = self.fallback.config.cutoff_m
        factor = factor or most_critical_factor(record, cutoff)
        try:
            reply = self.client.complete(
                EXPLAIN_PROMPT,
                situation_message(record, cutoff),
                self.client.config.explain_temperature,
            ).strip()
            problems = reply_problems(reply, record, factor, cutoff)
            if problems:
                raise BackendReplyError(f"explanation rejected: {'; '.join(problems)}")
            return Explanation(reply, factor, NAME, latency_s=time.perf_counter() - t0)
        except Exception as exc:
            error = _err(exc, self.client)
            log.warning("openai explanation failed, using templates: %s", error)
            return _as_fallback(self.fallback.explain(record, factor), t0, error)
