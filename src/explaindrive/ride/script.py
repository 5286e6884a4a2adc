"""Ride scripts: timed passenger lines, typed or spoken.

A script is a YAML or JSON list (or a mapping with a ``lines`` list)::

    - {t: 0, say: "I'm late for my train", confirm: yes}
    - {t: 70, audio: stop.wav}          # a spoken line, transcribed by Whisper
    - {t: 90, say: "take it easy now", confirm: no}

``t`` is the ride time in seconds; ``confirm`` answers the confirmation question
(``yes``/``no``; omitted: the ride's ``--auto-confirm`` decides, else the line
stays unconfirmed). Relative audio paths are resolved against the script's folder;
an audio file that does not exist is an error when the script is read.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path
from typing import Literal

import yaml
from pydantic import Field, ValidationError, field_validator, model_validator

from explaindrive.config import LaxModel
from explaindrive.ride.inputs import PassengerInput, SpokenLine, TypedLine
from explaindrive.validation import describe_errors


class ScriptError(ValueError):
    """A ride script cannot be read or is invalid."""


class ScriptLine(LaxModel):
    """One timed passenger line."""

    t: float = Field(ge=0, description="ride time [s] at which the passenger speaks")
    say: str | None = None
    audio: Path | None = None
    confirm: Literal["yes", "no"] | None = None

    @field_validator("confirm", mode="before")
    @classmethod
    def _yes_no(cls, value: object) -> object:
        if isinstance(value, bool):  # YAML reads bare yes/no as booleans
            return "yes" if value else "no"
        return value

    @model_validator(mode="after")
    def _one_source(self) -> ScriptLine:
        if (self.say is None) == (self.audio is None):
            raise ValueError("each line needs exactly one of 'say' or 'audio'")
        return self

    @property
    def answer(self) -> bool | None:
        """The scripted answer to the confirmation question: ``True`` for yes, ``False``
        for no, ``None`` when the line has none."""
        return None if self.confirm is None else self.confirm == "yes"

    @property
    def line(self) -> PassengerInput:
        """What the passenger says: the recording, else the typed text."""
        if self.audio is not None:
            return SpokenLine(self.audio)
        return TypedLine(self.say or "")


def _read(path: Path) -> object:
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScriptError(f"cannot read ride script {path}: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise ScriptError(
            f"ride script {path} is not UTF-8 text (byte {exc.start}: {exc.reason})"
        ) from exc
    try:
        if path.suffix.lower() == ".json":
            return json.loads(text)
        return yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise ScriptError(f"ride script {path} is not valid YAML/JSON: {exc}") from exc


def load_script(path: str | Path, max_time_s: float | None = None) -> list[ScriptLine]:
    """Read and validate a ride script, sorted by time.

    Args:
        path: the YAML/JSON file.
        max_time_s: the ride's length; a line after it is an error.

    Raises:
        ScriptError: naming the file and, where it applies, the line.
    """
    path = Path(path)
    data = _read(path)
    if isinstance(data, dict) and set(data) == {"lines"}:
        data = data["lines"]
    if not isinstance(data, list):
        raise ScriptError(f"ride script {path} must be a list of lines (or {{lines: [...]}})")
    lines: list[ScriptLine] = []
    for i, item in enumerate(data, start=1):
        if not isinstance(item, dict):
            raise ScriptError(f"ride script {path}, line {i}: expected a mapping, got {item!r}")
        try:
            line = ScriptLine.model_validate(item)
        except ValidationError as exc:
            raise ScriptError(
                f"ride script {path}, line {i}: {describe_errors(exc, root='line')}"
            ) from exc
        if line.audio is not None and not line.audio.is_absolute():
            line = line.model_copy(update={"audio": path.parent / line.audio})
        if line.audio is not None and not line.audio.is_file():
            raise ScriptError(f"ride script {path}, line {i}: audio file not found: {line.audio}")
        if max_time_s is not None and line.t > max_time_s:
            raise ScriptError(
                f"ride script {path}, line {i}: t={line.t:g} s is after the end of the ride "
                f"({max_time_s:g} s)"
            )
        lines.append(line)
    return sorted(lines, key=lambda ln: ln.t)


def default_script_path() -> Path:
    """The packaged script of ``explaindrive ride`` without options."""
    return Path(str(resources.files("explaindrive.ride") / "data" / "default_ride.yaml"))
