"""Passenger events: the one place that names their types.

Each step of a ride carries the passenger events that happened in it (``passenger`` in
``events.jsonl`` and in the web page's frames), each a dict with a ``type`` from
:class:`EventType` and the ride time ``t`` [s]. The page (``web/static/app.js``) has a line
of text for every type; ``tests/web/test_event_types.py`` keeps the two lists equal.
"""

from __future__ import annotations

from enum import StrEnum


class EventType(StrEnum):
    """The ``type`` of a passenger event; the value is what the files and the page hold."""

    LINE = "line"
    """A passenger line arrived: ``id``, ``text`` (or ``None``), ``audio`` (path or ``None``)."""
    TRANSCRIPT = "transcript"
    """A spoken line was transcribed: ``id``, ``text``, ``latency_s``."""
    INTERPRETATION = "interpretation"
    """A line was interpreted: ``id``, the intent result's fields, ``latency_s``, ``error``."""
    REPHRASE = "rephrase"
    """A line gave no text to interpret: ``id``, ``reason``, ``message`` for the passenger."""
    SUPERSEDED = "superseded"
    """A request was overtaken by a later one: ``id`` (and ``by``, the later request)."""
    CONFIRMED = "confirmed"
    """A command was confirmed: ``id``, ``source``, ``from`` and ``to`` (command labels)."""
    CANCELLED = "cancelled"
    """A command was declined: ``id``, ``answer``, ``source``, ``kept_command``."""
    LATE = "late"
    """A language module missed its deadline: ``module``, ``latency_s``, ``error`` (``None``),
    ``kept_command``."""
    ERROR = "error"
    """A language module failed: ``module``, ``latency_s``, ``error``, ``kept_command``."""
    ANSWER_IGNORED = "answer_ignored"
    """A yes/no answer came while no question was pending: ``reason``."""
