"""What the passenger gives the ride: typed text or a recording, never one disguised as
the other."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class TypedLine:
    """A line the passenger typed."""

    text: str


@dataclass(frozen=True)
class SpokenLine:
    """A line the passenger spoke, recorded in an audio file (WAV, FLAC, MP3)."""

    audio: Path


PassengerInput = TypedLine | SpokenLine
"""One passenger line, typed or spoken."""
