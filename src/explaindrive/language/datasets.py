"""Readers for the shipped language datasets (with clear errors on bad files).

* Command corpus: CSV with columns ``text,label[,kind]``; label fast|comfort|stop|none.
* Decision set: JSONL, one state record per line plus ``explain`` (bool) and
  ``factor`` labels (and an optional ``id`` / ``note``).
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from pydantic import ConfigDict, ValidationError

from explaindrive.language.decision import Factor
from explaindrive.language.summary import StateRecord
from explaindrive.validation import describe_errors

INTENT_LABELS: tuple[str, ...] = ("fast", "comfort", "stop", "none")


def data_path(name: str) -> Path:
    """Path of a file shipped in ``explaindrive/language/data``."""
    return Path(str(resources.files("explaindrive.language") / "data" / name))


TRAIN_CSV = "commands_train.csv"
"""Training requests."""
DEV_CSV = "commands_dev.csv"
"""Development requests: used for model selection and the STOP threshold."""
DEV2_CSV = "commands_dev2.csv"
"""Second development split (a former test split, evaluated once): selection and refit."""
DEV3_CSV = "commands_dev3.csv"
"""Third development split (a former test split, evaluated by two models)."""
DEV4_CSV = "commands_dev4.csv"
"""Fourth development split (a former test split, evaluated once)."""
DEV5_CSV = "commands_dev5.csv"
"""Fifth development split (a former test split, evaluated once)."""
DEV6_CSV = "commands_dev6.csv"
"""Sixth development split (the round-6 test split, evaluated by the round-6 model)."""
DEV7_CSV = "commands_dev7.csv"
"""Seventh development split (the round-7 test split, evaluated by the round-6 model)."""
DEV8_CSV = "commands_dev8.csv"
"""Eighth development split (the round-8 test split, evaluated by the round-8 model)."""
DEV9_CSV = "commands_dev9.csv"
"""Ninth development split (the round-9 test split, evaluated by the round-9 model)."""
DEV10_CSV = "commands_dev10.csv"
"""Tenth development split (the round-10 test split, evaluated by the round-10 model)."""
DEV11_CSV = "commands_dev11.csv"
"""The round-11 test split, evaluated once by the round-11 models."""
DEV12_CSV = "commands_dev12.csv"
"""The round-12 test split, evaluated once by the round-11 models and a withdrawn cascade."""
DEV13_CSV = "commands_dev13.csv"
"""The round-13 test split, evaluated once by the round-11 models."""
DEV14_CSV = "commands_dev14.csv"
"""The round-14 test split, evaluated once by the round-11 models."""
DEV_SPLITS: tuple[str, ...] = (
    DEV_CSV,
    DEV2_CSV,
    DEV3_CSV,
    DEV4_CSV,
    DEV5_CSV,
    DEV6_CSV,
    DEV7_CSV,
    DEV8_CSV,
    DEV9_CSV,
    DEV10_CSV,
    DEV11_CSV,
    DEV12_CSV,
    DEV13_CSV,
    DEV14_CSV,
)
"""The development splits, each written in its own round; LLM-1 selection holds each out."""
TEST10_CSV = "commands_test10.csv"
"""Held-out requests written from the labelling guide alone and committed before any
model judged on it was evaluated; never used to build a shipped model."""
TEST_CSV = "commands_test11.csv"
"""Held-out requests written from the labelling guide (self-corrections and off-topic
remarks that mention places, arrivals and stops included), committed before any model
was judged on it; never used to build a shipped model. The default of ``eval intents``."""
TEST_SPLITS: tuple[str, ...] = (TEST10_CSV, TEST_CSV)
DECISIONS_JSONL = "decisions.jsonl"
CLASSIFIER_NPZ = "intent_classifier.npz"
"""The shipped LLM-1 weights over all-MiniLM-L6-v2."""


@dataclass(frozen=True, slots=True)
class CommandExample:
    """One labelled passenger request; ``label`` is ``none`` for off-topic requests."""

    text: str
    label: str
    kind: str = ""


def load_commands(path: str | Path) -> list[CommandExample]:
    """Read a command CSV.

    Raises:
        FileNotFoundError: if the file is missing.
        ValueError: on missing columns, an empty text or an unknown label (with line number).
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"command file not found: {p}")
    with p.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        if reader.fieldnames is None or not {"text", "label"} <= set(reader.fieldnames):
            raise ValueError(f"{p}: expected a CSV header with columns text,label[,kind]")
        out: list[CommandExample] = []
        for line, row in enumerate(reader, start=2):
            text = (row.get("text") or "").strip()
            label = (row.get("label") or "").strip().lower()
            if not text:
                raise ValueError(f"{p}:{line}: empty text")
            if label not in INTENT_LABELS:
                raise ValueError(
                    f"{p}:{line}: unknown label {label!r}; expected one of {INTENT_LABELS}"
                )
            out.append(CommandExample(text, label, (row.get("kind") or "").strip()))
    if not out:
        raise ValueError(f"{p}: no rows")
    return out


class LabelledRecord(StateRecord):
    """A state record with its decision labels."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    explain: bool
    factor: Factor | None = None
    id: str | None = None
    note: str | None = None

    def record(self) -> StateRecord:
        """The unlabelled record (what the modules see)."""
        return StateRecord(request=self.request, action=self.action, state=self.state)


def load_decisions(path: str | Path) -> list[LabelledRecord]:
    """Read a decision JSONL file (blank lines are skipped).

    Raises:
        FileNotFoundError: if the file is missing.
        ValueError: on bad JSON or an invalid record, naming the line.
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"decision file not found: {p}")
    out: list[LabelledRecord] = []
    for line_no, line in enumerate(p.read_text(encoding="utf-8").splitlines(), start=1):
        if not line.strip():
            continue
        try:
            raw = json.loads(line)
        except json.JSONDecodeError as exc:
            raise ValueError(f"{p}:{line_no}: not valid JSON ({exc.msg})") from exc
        try:
            rec = LabelledRecord.model_validate(raw)
        except ValidationError as exc:
            raise ValueError(f"{p}:{line_no}: invalid record: {describe_errors(exc)}") from exc
        if rec.explain and rec.factor is None:
            raise ValueError(f"{p}:{line_no}: explain is true but factor is null")
        out.append(rec)
    if not out:
        raise ValueError(f"{p}: no records")
    return out
