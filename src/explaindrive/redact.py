"""Secrets out of text that reaches a log, an event file or a page.

A remote endpoint's error text can echo what it was sent, the API key included.
:func:`redact` replaces API keys (``sk-...``), bearer tokens, ``key=value`` pairs
whose name says they are secret, and any secret the caller names (the configured
key) with ``[redacted]``. :func:`redact_json` does the same through a JSON-ready
structure, and :class:`RedactingFilter` through log records.
"""

from __future__ import annotations

import logging
import os
import re
from collections.abc import Iterable
from typing import Any

MASK = "[redacted]"
MIN_SECRET_CHARS = 8  # shorter configured "keys" (placeholders like "test") are left alone
KEY_ENV_VARS = ("OPENAI_API_KEY",)  # keys the language backends read from the environment

_PATTERNS: tuple[tuple[re.Pattern[str], str], ...] = (
    # OpenAI-style keys: sk-..., sk-proj-...
    (re.compile(r"\bsk-[A-Za-z0-9_\-]{6,}"), MASK),
    # Authorization: Bearer <token>
    (re.compile(r"(?i)\b(bearer)\s+[A-Za-z0-9\-._~+/]+=*"), rf"\1 {MASK}"),
    # api_key=..., "apiKey": "...", access_token: ..., password=...
    (
        re.compile(
            r"(?i)\b((?:api[_-]?key|access[_-]?token|auth[_-]?token|secret|password|x-api-key)"
            r"[\"']?\s*[:=]\s*[\"']?)[^\s\"',;&}\]]+"
        ),
        rf"\1{MASK}",
    ),
)


def known_secrets(extra: Iterable[str | None] = ()) -> list[str]:
    """The secrets to mask literally: ``extra`` plus the keys set in the environment."""
    values = [*extra, *(os.environ.get(name) for name in KEY_ENV_VARS)]
    return sorted({v for v in values if v and len(v) >= MIN_SECRET_CHARS}, key=len, reverse=True)


def redact(text: str, secrets: Iterable[str | None] = ()) -> str:
    """``text`` with keys, bearer tokens, secret ``name=value`` pairs and ``secrets`` masked.

    Args:
        text: text that came from a remote endpoint (an error message, a reply).
        secrets: literal values to mask wherever they appear (the configured API key);
            the keys of :data:`KEY_ENV_VARS` are always included.
    """
    for secret in known_secrets(secrets):
        text = text.replace(secret, MASK)
    for pattern, replacement in _PATTERNS:
        text = pattern.sub(replacement, text)
    return text


def redact_json(obj: Any, secrets: Iterable[str | None] = ()) -> Any:
    """``obj`` with :func:`redact` applied to every string in it (dicts, lists, tuples)."""
    values = known_secrets(secrets)
    return _redact_tree(obj, values)


def _redact_tree(obj: Any, secrets: list[str]) -> Any:
    if isinstance(obj, str):
        return redact(obj, secrets)
    if isinstance(obj, dict):
        return {k: _redact_tree(v, secrets) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_redact_tree(v, secrets) for v in obj]
    return obj


class RedactingFilter(logging.Filter):
    """A logging filter that masks secrets in each record's formatted message."""

    def filter(self, record: logging.LogRecord) -> bool:
        """Replace the record's message by its redacted text; never drops a record."""
        message = record.getMessage()
        cleaned = redact(message)
        if cleaned != message:
            record.msg, record.args = cleaned, None
        if record.exc_info and not record.exc_text:
            record.exc_text = redact(logging.Formatter().formatException(record.exc_info))
        return True
