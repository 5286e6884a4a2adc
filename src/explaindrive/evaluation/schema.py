"""The JSON result file of an evaluation (documented in ``docs/evaluation.md``).

Layout (``version`` 1)::

    {
      "schema": "explaindrive-evaluation", "version": 1,
      "created_utc": "...", "explaindrive_version": "...",
      "runs": [
        {
          "name": "fast", "policy": {...PolicySpec...},
          "command": "fast", "schedule": [[60.0, "stop"], [75.0, "fast"]],
          "seeds": [0, 1], "traffic_levels": [0.5, 1.0], "max_steps": 1000,
          "aggregates": {"overall": {...Aggregate...}, "by_level": {"0.5": {...}, ...}},
          "paper": {...PaperRow...} | null,
          "episodes": [
            {"seed": 0, "traffic_level": 0.5, "metrics": {...EpisodeResult...},
             "shield_overrides": 3,
             "trace": {"speed_mps": [...], "command": [...]}}
          ]
        }
      ]
    }
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from explaindrive.env.metrics import EpisodeResult
from explaindrive.evaluation.aggregate import aggregate, aggregate_by_level
from explaindrive.evaluation.paper import paper_row
from explaindrive.evaluation.runner import EpisodeRecord
from explaindrive.jsonsafe import finite

SCHEMA_NAME = "explaindrive-evaluation"
SCHEMA_VERSION = 1


def _unique(values: Sequence[Any]) -> list[Any]:
    return list(dict.fromkeys(values))


def episode_document(record: EpisodeRecord, include_trace: bool = True) -> dict[str, Any]:
    """JSON-ready dict of one episode."""
    doc: dict[str, Any] = {
        "seed": record.spec.seed,
        "traffic_level": record.spec.traffic_level,
        "metrics": record.result.as_dict(),
        "shield_overrides": record.shield_overrides,
    }
    if include_trace:
        doc["trace"] = {"speed_mps": list(record.speeds_mps), "command": list(record.commands)}
    return doc


def run_document(
    name: str, records: Sequence[EpisodeRecord], include_traces: bool = True
) -> dict[str, Any]:
    """JSON-ready dict of one run: a policy under one schedule over a seed x level grid.

    Raises:
        ValueError: if ``records`` is empty or mixes policies or schedules.
    """
    if not records:
        raise ValueError(f"run {name!r} has no episodes")
    first = records[0].spec
    for rec in records:
        if (rec.spec.policy, rec.spec.command, rec.spec.schedule) != (
            first.policy, first.command, first.schedule,
        ):  # fmt: skip
            raise ValueError(f"run {name!r} mixes policies or command schedules")
    by_level = aggregate_by_level([(r.spec.traffic_level, r.result) for r in records])
    paper = paper_row(name)
    return {
        "name": name,
        "policy": first.policy.as_dict(),
        "command": first.command,
        "schedule": [[t, c] for t, c in first.schedule],
        "seeds": _unique([r.spec.seed for r in records]),
        "traffic_levels": _unique([r.spec.traffic_level for r in records]),
        "max_steps": first.max_steps,
        "aggregates": {
            "overall": aggregate([r.result for r in records]).as_dict(),
            "by_level": {f"{level:g}": agg.as_dict() for level, agg in by_level.items()},
        },
        "paper": dataclasses.asdict(paper) if paper else None,
        "episodes": [episode_document(r, include_traces) for r in records],
    }


def evaluation_document(runs: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The whole file: header plus ``runs`` (from :func:`run_document`)."""
    try:
        version = metadata.version("explaindrive")
    except metadata.PackageNotFoundError:
        version = "unknown"
    return finite(
        {
            "schema": SCHEMA_NAME,
            "version": SCHEMA_VERSION,
            "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
            "explaindrive_version": version,
            "runs": list(runs),
        }
    )


def write_json(path: Path, runs: Sequence[dict[str, Any]]) -> Path:
    """Write :func:`evaluation_document` of ``runs`` to ``path`` (parents created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    doc = evaluation_document(runs)
    # Paper rows have float keys; JSON object keys become strings.
    path.write_text(json.dumps(doc, indent=1, allow_nan=False, default=str) + "\n", "utf-8")
    return path


@dataclasses.dataclass(frozen=True, slots=True)
class StoredRun:
    """One run read back from an evaluation file: its name, what drove and its episodes as
    ``(traffic level, seed, result)``."""

    name: str
    policy: dict[str, Any]
    episodes: tuple[tuple[float, int, EpisodeResult], ...]


def read_runs(path: Path) -> list[StoredRun]:
    """The runs of an evaluation file (:func:`write_json`), for example one that a driver
    evaluated outside ``explaindrive evaluate`` wrote.

    Raises:
        ValueError: naming the file and what is wrong with it (missing, not JSON, another
            schema, a run or an episode without its figures).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"evaluation file not found: {path}")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path} is not JSON: {exc}") from None
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA_NAME:
        raise ValueError(f"{path} is not an {SCHEMA_NAME} file (no schema {SCHEMA_NAME!r})")
    runs = []
    for k, run in enumerate(doc.get("runs") or []):
        try:
            episodes = tuple(
                (float(e["traffic_level"]), int(e["seed"]), EpisodeResult.from_dict(e["metrics"]))
                for e in run["episodes"]
            )
            runs.append(StoredRun(str(run["name"]), dict(run.get("policy") or {}), episodes))
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: run {k} cannot be read: {exc!r}") from None
        if not episodes:
            raise ValueError(f"{path}: run {run['name']!r} has no episodes (written with "
                             "--no-episodes?)")  # fmt: skip
    if not runs:
        raise ValueError(f"{path} holds no runs")
    return runs
