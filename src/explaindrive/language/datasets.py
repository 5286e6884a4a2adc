"""Readers for the shipped language data (with clear errors on bad files).

* Command files: CSV with columns ``text,label[,kind][,split]``. ``label`` is fast, comfort,
  stop or none (off-topic); ``kind`` says what sort of request it is (direct, indirect,
  negation, noise, offtopic, correction, tampered).
* Decision file: JSONL, one state record per line plus ``explain`` (bool) and ``factor``
  labels (and an optional ``id`` / ``note``).

The ``split`` column of :data:`TRAIN_CSV` says what building LLM-1 does with a request:

* ``train``: always fitted on.
* ``dev-1`` ... ``dev-N``: the development splits. For the choice of hyper-parameters, the
  STOP threshold and the none margin, each is predicted by a model fitted on ``train`` and
  the other development splits; the shipped model is then fitted on ``train`` and all of
  them (:mod:`explaindrive.language.intent_training`).
* ``reserve``: neither fitted on nor used for choices by the shipped model; free for checks
  and for a later model's development.
"""

from __future__ import annotations

import csv
import json
import re
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from pydantic import ConfigDict, ValidationError

from explaindrive.language.decision import Factor
from explaindrive.language.summary import StateRecord
from explaindrive.validation import describe_errors

INTENT_LABELS: tuple[str, ...] = ("fast", "comfort", "stop", "none")
TRAIN_SPLIT = "train"
DEV_PREFIX = "dev-"
RESERVE_SPLIT = "reserve"
_SPLIT = re.compile(rf"{TRAIN_SPLIT}|{RESERVE_SPLIT}|{DEV_PREFIX}[1-9][0-9]*")

TRAIN_CSV = "commands_train.csv"
"""Every labelled request a model may be built or selected on; the split column says how."""
TEST_CSV = "commands_test.csv"
"""The blind test requests, never used to build or select a model."""
BLIND_CSV = "commands_blind.csv"
"""A second blind test split, written for the readings the first one missed: negated stops,
complaints that mention lights, stops or arriving, self-corrections, hedges, typos and
speech-recognition errors, polite, terse and rude phrasings, and off-topic remarks that
use driving words. Never used to build or select a model."""
DECISIONS_JSONL = "decisions.jsonl"
"""Labelled state records for the LLM-2 trigger and the LLM-3 explanations."""
CLASSIFIER_NPZ = "intent_classifier.npz"
"""The shipped LLM-1 weights over all-MiniLM-L6-v2."""


def data_path(name: str) -> Path:
    """Path of a file shipped in ``explaindrive/language/data``."""
    return Path(str(resources.files("explaindrive.language") / "data" / name))


@dataclass(frozen=True, slots=True)
class CommandExample:
    """One labelled passenger request; ``label`` is ``none`` for off-topic requests and
    ``split`` is empty in a file without that column."""

    text: str
    label: str
    kind: str = ""
    split: str = ""


def load_commands(path: str | Path) -> list[CommandExample]:
    """Read a command CSV.

    Raises:
        FileNotFoundError: if the file is missing.
        ValueError: on missing columns, an empty text, an unknown label or split (with line
            number).
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"command file not found: {p}")
    with p.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        if reader.fieldnames is None or not {"text", "label"} <= set(reader.fieldnames):
            raise ValueError(f"{p}: expected a CSV header with columns text,label[,kind][,split]")
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
            split = (row.get("split") or "").strip()
            if "split" in reader.fieldnames and not _SPLIT.fullmatch(split):
                raise ValueError(
                    f"{p}:{line}: unknown split {split!r}; expected {TRAIN_SPLIT}, "
                    f"{DEV_PREFIX}<k> or {RESERVE_SPLIT}"
                )
            out.append(CommandExample(text, label, (row.get("kind") or "").strip(), split))
    if not out:
        raise ValueError(f"{p}: no rows")
    return out


def training_splits(
    rows: list[CommandExample],
) -> tuple[list[CommandExample], list[list[CommandExample]]]:
    """The ``train`` requests and the development splits ``dev-1`` ... ``dev-N`` in order,
    each in file order; ``reserve`` requests are left out.

    Raises:
        ValueError: if there are no ``train`` requests, or the development splits are not
            numbered 1 to N.
    """
    train = [r for r in rows if r.split == TRAIN_SPLIT]
    devs: dict[int, list[CommandExample]] = {}
    for r in rows:
        if r.split.startswith(DEV_PREFIX):
            devs.setdefault(int(r.split.removeprefix(DEV_PREFIX)), []).append(r)
    if not train:
        raise ValueError(f"no requests of split {TRAIN_SPLIT!r}")
    if sorted(devs) != list(range(1, len(devs) + 1)):
        numbers = ", ".join(map(str, sorted(devs)))
        raise ValueError(f"development splits must be numbered 1 to N, got {numbers}")
    return train, [devs[k] for k in sorted(devs)]


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
