"""The pools LLM-1 is trained and calibrated on, and the reader of their files."""

from __future__ import annotations

import gzip
from pathlib import Path

import pytest

from explaindrive.language.intent.corpus import (
    calibration_pool,
    external_check,
    read_lines,
    training_pool,
)


def test_read_lines_reads_plain_and_gzip_files_and_names_bad_ones(tmp_path: Path) -> None:
    (tmp_path / "a.csv").write_text('text,label\n"hi, there",none\n', encoding="utf-8")
    with gzip.open(tmp_path / "a.csv.gz", "wt", encoding="utf-8") as fh:
        fh.write("text,source\nhello,x\n")
    assert read_lines(tmp_path / "a.csv") == [{"text": "hi, there", "label": "none"}]
    assert read_lines(tmp_path / "a.csv.gz") == [{"text": "hello", "source": "x"}]
    with pytest.raises(FileNotFoundError, match="not found"):
        read_lines(tmp_path / "missing.csv")
    (tmp_path / "b.csv").write_text("words,label\nhi,none\n", encoding="utf-8")
    with pytest.raises(ValueError, match="text column"):
        read_lines(tmp_path / "b.csv")
    (tmp_path / "c.csv").write_text("text,label\nhi,none\n ,none\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"c.csv:3: empty text"):
        read_lines(tmp_path / "c.csv")


def test_the_calibration_pool_is_never_trained_on() -> None:
    labelled, everyday = training_pool()
    pool = calibration_pool()
    trained = {e.text for e in labelled} | {e.text for e in everyday}
    assert not trained & {e.text for e in pool}
    assert len(everyday) > 20_000 and {e.label for e in everyday} == {"none"}
    labels = {e.label for e in labelled}
    assert labels == {"fast", "comfort", "stop", "none", "why", "yes", "no"}
    checked = set(external_check())
    assert len(checked) >= 1000 and not checked & (trained | {e.text for e in pool})


def test_answers_and_questions_about_the_car_are_learned_as_readings_not_as_none() -> None:
    labelled, _ = training_pool()
    # the former test splits label "No." and "Why did you brake?" none (no command); the
    # training pool takes those readings from commands_written.csv alone
    sources = {e.source.split(":")[0] for e in labelled if e.source.endswith((":why", ":answer"))}
    assert not any(name.startswith("commands_heldout") for name in sources)
    by_text: dict[str, set[str]] = {}
    for e in labelled:
        by_text.setdefault(e.text.lower(), set()).add(e.label)
    assert by_text["no."] == {"no"}  # commands_heldout5.csv holds "No." labelled none
    readings = {t for t, labels in by_text.items() if labels & {"why", "yes", "no"}}
    assert all(len(by_text[t]) == 1 for t in readings)  # no line is taught two readings
