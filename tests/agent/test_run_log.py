"""The training log: an older ``episodes.csv`` gains the columns a resumed run writes."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from explaindrive.agent.run_log import CSV_FIELDS, upgrade_csv


def test_an_older_log_gains_the_yield_column_with_its_rows_kept(tmp_path: Path) -> None:
    old = [name for name in CSV_FIELDS if name != "yield_violation"]
    path = tmp_path / "episodes.csv"
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=old)
        writer.writeheader()
        writer.writerow({name: str(i) for i, name in enumerate(old)})
    upgrade_csv(path)
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == list(CSV_FIELDS)
    assert rows[0]["yield_violation"] == ""
    assert rows[0]["episode"] == "0" and rows[0]["wall_time_s"] == str(len(old) - 1)


def test_a_file_with_an_unknown_column_is_refused_untouched(tmp_path: Path) -> None:
    path = tmp_path / "episodes.csv"
    path.write_text("episode,reward_of_something_else\n1,2\n")
    with pytest.raises(ValueError, match="unknown column 'reward_of_something_else'"):
        upgrade_csv(path)
    assert path.read_text() == "episode,reward_of_something_else\n1,2\n"
