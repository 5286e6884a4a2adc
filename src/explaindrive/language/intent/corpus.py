"""The lines LLM-1 learns from and is calibrated on, read from ``language/data``.

* Requests (``commands_train.csv``): labelled passenger requests; its ``reserve`` split is
  kept for calibration. The previous test splits (``FORMER_HELDOUT_CSVS``, development
  splits now) are trained on, but for their questions about the car and answers
  (:data:`SPLIT_ONLY_KINDS`).
* Written lines (``commands_written.csv``): in-car chatter and phone talk that use pace and
  stopping words in other senses, questions about the car's behaviour (``why``), answers
  to a confirmation (``yes`` / ``no``), negated requests; one line in seven (by a hash of
  the text) is kept for calibration.
* Everyday lines with driving words (``everyday_driving_words.csv``): lines of the everyday
  corpora that use words of pace or stopping, labelled by a reader outside the project;
  one line in seven is kept for calibration, as for the written lines.
* Everyday language (``everyday_train.csv.gz``, built by
  ``scripts/build_everyday_corpus.py`` from corpora public packages ship): no command;
  its ``calibration`` split is kept for calibration.
* The development splits ``commands_test.csv`` and ``commands_blind.csv`` are calibrated on,
  never trained on.

The test split (``HELDOUT_CSV``) and the external check ``everyday_check.csv.gz``
are read by the evaluation only.
"""

from __future__ import annotations

import csv
import gzip
import hashlib
import io
from collections.abc import Iterable
from dataclasses import dataclass
from difflib import SequenceMatcher
from pathlib import Path

from explaindrive.language.data import (
    DEVELOPMENT_CSVS,
    EVERYDAY_CHECK,
    EVERYDAY_TRAIN,
    EVERYDAY_WORDS_CSV,
    FORMER_HELDOUT_CSVS,
    TRAIN_CSV,
    WRITTEN_CSV,
    data_path,
)
from explaindrive.language.intent.model import READINGS

RESERVE = "reserve"
NEAR_COPY = 0.8
"""Character similarity (difflib's ratio, either way round) from which a line counts as a
near-copy of another: no line near the test split is trained or calibrated on."""
HASH_SPLIT_CSVS = (WRITTEN_CSV, EVERYDAY_WORDS_CSV)
"""The labelled files split between training and calibration by a hash of each line's text."""
HASH_HOLDOUT = 7  # one line of those files in this many is kept for calibration
SPLIT_ONLY_KINDS = frozenset({"why", "answer"})
"""Kinds of line a test split labels ``none`` (no command) that LLM-1 reads as ``why``,
``yes`` or ``no``: the former test splits' lines of these kinds are not trained on, since
their label is the split's, not the reading ("Yes." labelled none would teach the model
not to hear an answer); ``commands_written.csv`` teaches those readings."""


@dataclass(frozen=True, slots=True)
class Example:
    """One labelled line: ``label`` is one of :data:`READINGS`; ``source`` says where it
    comes from (a file name, or ``file:kind``)."""

    text: str
    label: str
    source: str


def read_lines(path: Path) -> list[dict[str, str]]:
    """The rows of a CSV file, gzip-compressed or not.

    Raises:
        FileNotFoundError: if the file is missing.
        ValueError: if it has no ``text`` column or an empty text (naming the line).
    """
    if not path.is_file():
        raise FileNotFoundError(f"language data file not found: {path}")
    raw = path.read_bytes()
    text = gzip.decompress(raw).decode("utf-8") if path.suffix == ".gz" else raw.decode("utf-8")
    reader = csv.DictReader(io.StringIO(text))
    if reader.fieldnames is None or "text" not in reader.fieldnames:
        raise ValueError(f"{path}: expected a CSV header with a text column")
    rows = []
    for line, row in enumerate(reader, start=2):
        if not (row.get("text") or "").strip():
            raise ValueError(f"{path}:{line}: empty text")
        rows.append({k: (v or "").strip() for k, v in row.items() if k is not None})
    return rows


def _labelled(path: Path) -> list[tuple[Example, dict[str, str]]]:
    out = []
    for row in read_lines(path):
        label = row.get("label", "").lower()
        if label not in READINGS:
            raise ValueError(f"{path}: unknown label {label!r} for {row['text']!r}")
        out.append((Example(row["text"], label, f"{path.name}:{row.get('kind', '')}"), row))
    return out


def _held_out(text: str) -> bool:
    digest = hashlib.sha256(text.lower().encode("utf-8")).hexdigest()
    return int(digest, 16) % HASH_HOLDOUT == 0


def training_pool() -> tuple[list[Example], list[Example]]:
    """The labelled lines and the everyday lines (label ``none``) LLM-1 is trained on."""
    labelled = [e for e, row in _labelled(data_path(TRAIN_CSV)) if row.get("split") != RESERVE]
    for name in FORMER_HELDOUT_CSVS:
        labelled += [
            e for e, row in _labelled(data_path(name)) if row.get("kind") not in SPLIT_ONLY_KINDS
        ]
    for name in HASH_SPLIT_CSVS:
        labelled += [e for e, _ in _labelled(data_path(name)) if not _held_out(e.text)]
    everyday = [
        Example(row["text"], "none", f"{EVERYDAY_TRAIN}:{row['source']}")
        for row in read_lines(data_path(EVERYDAY_TRAIN))
        if row.get("split") == "train"
    ]
    return labelled, everyday


def calibration_pool() -> list[Example]:
    """The lines the thresholds are chosen on; none of them is trained on (a line that
    also occurs in the training pool, such as a short reply, is left out)."""
    labelled, everyday = training_pool()
    trained = {e.text.lower() for e in labelled} | {e.text.lower() for e in everyday}
    pool = [e for e, row in _labelled(data_path(TRAIN_CSV)) if row.get("split") == RESERVE]
    for name in HASH_SPLIT_CSVS:
        pool += [e for e, _ in _labelled(data_path(name)) if _held_out(e.text)]
    for name in DEVELOPMENT_CSVS:
        pool += [e for e, _ in _labelled(data_path(name))]
    pool += [
        Example(row["text"], "none", f"{EVERYDAY_TRAIN}:{row['source']}")
        for row in read_lines(data_path(EVERYDAY_TRAIN))
        if row.get("split") == "calibration"
    ]
    return [e for e in pool if e.text.lower() not in trained]


def external_check() -> list[str]:
    """The external check's lines (everyday talk no model was trained or selected on)."""
    return [row["text"] for row in read_lines(data_path(EVERYDAY_CHECK))]


def near_copies(tests: Iterable[str], seen: Iterable[str]) -> set[str]:
    """The lines of ``seen`` that are near-copies of a line of ``tests`` (compared in lower
    case; difflib's ratio, which is not symmetric, at least :data:`NEAR_COPY` either way
    round). One matcher per second sequence, whose tables difflib caches, keeps this fast.
    """
    tests_l = sorted({t.lower() for t in tests})
    seen_by: dict[str, str] = {}
    for s in seen:
        seen_by.setdefault(s.lower(), s)
    near: set[str] = set()
    for firsts, seconds, flip in ((tests_l, list(seen_by), False), (list(seen_by), tests_l, True)):
        for b in seconds:
            m = SequenceMatcher(None, "", b)
            for a in firsts:
                if 2 * min(len(a), len(b)) < NEAR_COPY * (len(a) + len(b)):
                    continue  # real_quick_ratio from the lengths alone
                m.set_seq1(a)
                if m.quick_ratio() >= NEAR_COPY and m.ratio() >= NEAR_COPY:
                    near.add(seen_by[a if flip else b])
    return near
