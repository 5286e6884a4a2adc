"""Readers for LLM-1's command files (with clear errors on bad files).

A command file is a CSV with columns ``text,label[,kind][,split]``. ``label`` is fast,
comfort, stop or none (off-topic); ``kind`` says what sort of request it is (direct,
indirect, negation, noise, offtopic, correction, tampered). The shipped files are named in
:mod:`explaindrive.language.data`.

The ``split`` column of :data:`~explaindrive.language.data.TRAIN_CSV` says what building
LLM-1 does with a request: ``train`` and the former development splits ``dev-1`` ...
``dev-N`` are fine-tuned on; ``reserve`` is kept for the calibration of the thresholds
(:mod:`explaindrive.language.intent.corpus`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from explaindrive.language.intent.corpus import read_lines

INTENT_LABELS: tuple[str, ...] = ("fast", "comfort", "stop", "none")
TRAIN_SPLIT = "train"
DEV_PREFIX = "dev-"
RESERVE_SPLIT = "reserve"
UNSEEN_SPLIT = "unseen"
"""Of a test split: a line with no near-copy among the lines a model learns or is calibrated
from (``intent.corpus.near_copies``) when the split was committed; ``near`` one with one."""
NEAR_SPLIT = "near"
_SPLIT = re.compile(
    rf"{TRAIN_SPLIT}|{RESERVE_SPLIT}|{UNSEEN_SPLIT}|{NEAR_SPLIT}|{DEV_PREFIX}[1-9][0-9]*"
)


@dataclass(frozen=True, slots=True)
class CommandExample:
    """One labelled passenger request; ``label`` is ``none`` for off-topic requests and
    ``split`` is empty in a file without that column."""

    text: str
    label: str
    kind: str = ""
    split: str = ""


def load_commands(path: str | Path) -> list[CommandExample]:
    """Read a command CSV (plain or gzip-compressed, by
    :func:`~explaindrive.language.intent.corpus.read_lines`).

    Raises:
        FileNotFoundError: if the file is missing.
        ValueError: on missing columns, an empty text, an unknown label or split (with line
            number).
    """
    p = Path(path)
    rows = read_lines(p)
    if not rows:
        raise ValueError(f"{p}: no rows")
    columns = set(rows[0])
    if not {"text", "label"} <= columns:
        raise ValueError(f"{p}: expected a CSV header with columns text,label[,kind][,split]")
    out: list[CommandExample] = []
    for line, row in enumerate(rows, start=2):
        label = row.get("label", "").lower()
        if label not in INTENT_LABELS:
            raise ValueError(
                f"{p}:{line}: unknown label {label!r}; expected one of {INTENT_LABELS}"
            )
        split = row.get("split", "")
        if "split" in columns and not _SPLIT.fullmatch(split):
            raise ValueError(
                f"{p}:{line}: unknown split {split!r}; expected {TRAIN_SPLIT}, "
                f"{DEV_PREFIX}<k>, {RESERVE_SPLIT}, {UNSEEN_SPLIT} or {NEAR_SPLIT}"
            )
        out.append(CommandExample(row["text"], label, row.get("kind", ""), split))
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
