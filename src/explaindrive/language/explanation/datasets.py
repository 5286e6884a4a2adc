"""Reader for the decision file of LLM-2 and LLM-3 (with clear errors on bad files).

The decision file is JSONL: one state record per line plus ``explain`` (bool) and
``factor`` labels (and an optional ``id`` / ``note``). The shipped file is
:data:`~explaindrive.language.data.DECISIONS_JSONL`.
"""

from __future__ import annotations

import json
from pathlib import Path

from pydantic import ConfigDict, ValidationError

from explaindrive.language.explanation.decision import Factor
from explaindrive.language.explanation.summary import StateRecord
from explaindrive.validation import describe_errors


class LabelledRecord(StateRecord):
    """A state record with its decision labels."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    explain: bool
    factor: Factor | None = None
    id: str | None = None
    note: str | None = None

    def record(self) -> StateRecord:
        """The unlabelled record (what the modules see)."""
        return StateRecord(
            request=self.request, action=self.action, state=self.state, history=self.history
        )


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
