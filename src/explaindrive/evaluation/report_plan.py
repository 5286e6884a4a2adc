"""The runs of ``docs/results.md``: which policies, grids and stop injections it evaluates.

:func:`parse_policy_list` reads the ``--policies`` text; :func:`plan_report` turns the
policies into a :class:`ReportPlan`: each agent and baseline alone and with the paper's stop
injections, and the merged controller's single episode.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from explaindrive.evaluation.paper import PAPER_MERGED_COMMANDS, PAPER_STOP_SCHEDULE
from explaindrive.evaluation.parsing import SpecError
from explaindrive.evaluation.spec import (
    MERGED,
    POLICY_NAMES,
    PolicySpec,
    RunPlan,
    parse_policy,
    plan_run,
)


@dataclass(frozen=True, slots=True)
class ReportPlan:
    """The runs of the results document.

    Attributes:
        runs: every run, in document order.
        policies: the resolved policies by name.
        seeds: seeds of every grid run.
        levels: traffic levels of every grid run.
    """

    runs: tuple[RunPlan, ...]
    policies: dict[str, PolicySpec]
    seeds: tuple[int, ...]
    levels: tuple[float, ...]


def parse_policy_list(text: str) -> tuple[str, ...]:
    """Parse ``fast,comfort,merged,krauss,idm`` (any subset, no duplicates).

    Raises:
        SpecError: on an unknown or repeated name.
    """
    names = [n.strip().lower() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in POLICY_NAMES]
    if not names or unknown:
        raise SpecError(f"policies must be among {', '.join(POLICY_NAMES)}; got {text!r}")
    if len(set(names)) != len(names):
        raise SpecError(f"policy list {text!r} repeats a name")
    return tuple(names)


def plan_report(
    policies: Sequence[str],
    seeds: Sequence[int],
    levels: Sequence[float],
    *,
    merged_seed: int = 0,
    merged_level: float = 1.0,
    fast_path: str | Path | None = None,
    comfort_path: str | Path | None = None,
    max_steps: int = 1000,
    shield: bool = True,
) -> ReportPlan:
    """Lay out the runs: each agent and baseline alone and with the paper's stop injections,
    and the merged fast -> stop -> comfort single episode.

    Raises:
        SpecError: on a missing policy file or an invalid grid.
    """
    resolved: dict[str, PolicySpec] = {}
    runs: list[RunPlan] = []
    for name in policies:
        spec = parse_policy(name, fast_path=fast_path, comfort_path=comfort_path, shield=shield)
        resolved[name] = spec
        if name == MERGED:
            runs.append(
                plan_run(
                    spec,
                    (merged_seed,),
                    (merged_level,),
                    commands=PAPER_MERGED_COMMANDS,
                    max_steps=max_steps,
                )
            )
            continue
        runs.append(plan_run(spec, seeds, levels, max_steps=max_steps))
        runs.append(
            plan_run(spec, seeds, levels, stop_schedule=PAPER_STOP_SCHEDULE, max_steps=max_steps)
        )
    return ReportPlan(tuple(runs), resolved, tuple(seeds), tuple(levels))
