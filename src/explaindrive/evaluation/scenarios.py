"""Evaluating on several scenarios: generated ones held out from training, and own networks.

``random:100-119`` names generated scenarios 100 to 119
(:func:`~explaindrive.sim.scenario.generator.random_params`); their seeds must lie below
:data:`~explaindrive.sim.scenario.generator.TRAIN_SEED_START`, where training draws begin,
so they are never trained on. Each is built once (netconvert) before the episodes run.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from explaindrive.evaluation.parsing import SpecError, parse_seeds
from explaindrive.evaluation.spec import RunPlan

RANDOM_PREFIX = "random:"


@dataclass(frozen=True, slots=True)
class ScenarioCase:
    """One scenario of an evaluation: its name and the env config fields choosing it."""

    name: str
    fields: tuple[tuple[str, Any], ...]


PAPER_ROAD = ScenarioCase("paper", ())
"""The paper's road: no fields choose another scenario."""


def parse_scenarios(text: str, cache_dir: Path) -> tuple[ScenarioCase, ...]:
    """``random:SEEDS`` (e.g. ``random:100-119``) as built, held-out generated scenarios.

    Raises:
        SpecError: on another form, a bad seed list or a seed that training may draw.
    """
    from explaindrive.sim.scenario.generator import TRAIN_SEED_START

    if not text.startswith(RANDOM_PREFIX):
        raise SpecError(f"scenarios {text!r} must look like random:SEEDS (e.g. random:100-119)")
    seeds = parse_seeds(text[len(RANDOM_PREFIX) :])
    drawn = [s for s in seeds if s >= TRAIN_SEED_START]
    if drawn:
        raise SpecError(
            f"scenario seed(s) {drawn[:3]} are not held out: training draws seeds from "
            f"{TRAIN_SEED_START} on; use seeds below it"
        )
    return tuple(random_case(seed, cache_dir) for seed in seeds)


def random_case(seed: int, cache_dir: Path) -> ScenarioCase:
    """Generated scenario ``seed``, built into the cache if needed."""
    from explaindrive.sim.scenario.directory import cached_scenario_dir
    from explaindrive.sim.scenario.generator import random_params

    name = f"random-{seed}"
    directory = cached_scenario_dir(random_params(seed), name, cache_dir, seed)
    return ScenarioCase(name, (("scenario", str(directory)),))


def network_case(name: str, fields: dict[str, Any]) -> ScenarioCase:
    """An own network (``net_file``, ``route``, optional ``demand_file``) as a case."""
    return ScenarioCase(name, tuple(sorted(fields.items())))


def over_scenarios(plan: RunPlan, cases: Sequence[ScenarioCase]) -> RunPlan:
    """The plan's grid repeated in every scenario, scenario-major."""
    episodes = tuple(
        dataclasses.replace(ep, scenario=case.fields, scenario_name=case.name)
        for case in cases
        for ep in plan.episodes
    )
    return dataclasses.replace(plan, episodes=episodes)


def by_scenario(records: Sequence[Any]) -> dict[str, list[Any]]:
    """Episode records grouped by scenario name, in the order they first appear."""
    groups: dict[str, list[Any]] = {}
    for rec in records:
        groups.setdefault(rec.spec.scenario_name, []).append(rec)
    return groups
