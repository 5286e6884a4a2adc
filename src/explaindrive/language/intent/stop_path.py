"""STOP's explicit path: a few phrases that always ask the car to stop.

Everything else LLM-1 reads is learned. STOP alone keeps this small, written-down path as
well, for recall: a line that names an emergency or one of the plainest ways of asking to
be let out is read as STOP even when the model is unsure of it (a speech-recognition
garble around "pull over", say). The model can still overrule the path when it is sure of
another reading: "don't pull over, just drive gently" is comfort, and "no need to pull
over" asks for nothing.
"""

from __future__ import annotations

import re

STOP_PHRASES: tuple[str, ...] = (
    r"emergency",
    r"pull (over|in|up)",
    r"let me (out|off)",
    r"drop me (off )?(here|now|right)",
    r"stop the car",
    r"stop (here|now|right here)",
)
"""The phrases (regular expressions, matched as whole words, any case)."""
_PATTERN = re.compile(r"\b(" + "|".join(STOP_PHRASES) + r")\b", re.IGNORECASE)


def names_stop(text: str) -> bool:
    """Whether ``text`` holds one of :data:`STOP_PHRASES`."""
    return _PATTERN.search(text) is not None
