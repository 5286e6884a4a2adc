"""What to evaluate: policies and the episode grids they run over.

A policy name or file becomes a :class:`PolicySpec`; a policy with seeds, traffic levels and
a command schedule becomes a :class:`RunPlan`, a grid of :class:`EpisodeSpec`. The text formats of
seeds, levels and schedules are parsed in :mod:`explaindrive.evaluation.parsing`; every
error here is a :class:`~explaindrive.evaluation.parsing.SpecError` too.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from explaindrive.commands import COMMAND_LABELS, Command
from explaindrive.evaluation.parsing import (
    SpecError,
    parse_commands,
    parse_stop_schedule,
    segments_to_schedule,
    stops_to_schedule,
)
from explaindrive.limits import MAX_STEPS

BASELINES: tuple[str, ...] = ("krauss", "idm")
AGENTS: tuple[str, ...] = ("fast", "comfort")
MERGED = "merged"
POLICY_NAMES: tuple[str, ...] = (*AGENTS, MERGED, *BASELINES)
DEFAULT_MAX_STEPS = 1000  # [steps of 1 s] episode limit, as in the env's default


@dataclass(frozen=True, slots=True)
class PolicySpec:
    """A policy to evaluate; picklable, so it travels to worker processes and Ray tasks.

    Attributes:
        name: label in tables and files (``fast``, ``merged``, ``krauss``, a file stem...).
        kind: ``"agent"`` (one Q-network), ``"merged"`` (fast + comfort) or ``"baseline"``.
        paths: policy files: one for an agent, (fast, comfort) for merged, none for baselines.
        ego_model: the env's ``ego_model``: ``"agent"``, ``"krauss"`` or ``"idm"``.
        primary: the command the policy drives under when no schedule says otherwise.
        shield: agents act through the kinematic safety shield (``agent/shield.py``).
    """

    name: str
    kind: str
    paths: tuple[str, ...]
    ego_model: str
    primary: str
    shield: bool = True

    @property
    def allowed_commands(self) -> tuple[str, ...]:
        """Commands this policy may be given: an agent knows its own command and stop."""
        if self.kind == "agent":
            return (self.primary, Command.STOP.label)
        return COMMAND_LABELS

    def as_dict(self) -> dict[str, object]:
        """JSON-ready dict."""
        return {"name": self.name, "kind": self.kind, "paths": list(self.paths),
                "ego_model": self.ego_model, "primary": self.primary,
                "shield": self.shield if self.kind != "baseline" else None}  # fmt: skip


@dataclass(frozen=True, slots=True)
class EpisodeSpec:
    """One episode of a grid.

    Attributes:
        policy: what drives.
        seed: SUMO and pedestrian seed.
        traffic_level: demand scale.
        command: command from the first step (label).
        schedule: ``(time_s, command label)`` switches after the start.
        max_steps: step limit [steps of 1 s].
        obs_noise: ``(sd_m, sd_mps)`` of the noise on what the driver sees
            (:mod:`explaindrive.env.noise`); SUMO's drivers see the true state.
        scenario: env config fields choosing the scenario (none: the paper's road).
        scenario_name: how tables name that scenario.
    """

    policy: PolicySpec
    seed: int
    traffic_level: float
    command: str
    schedule: tuple[tuple[float, str], ...]
    max_steps: int = DEFAULT_MAX_STEPS
    obs_noise: tuple[float, float] = (0.0, 0.0)
    scenario: tuple[tuple[str, Any], ...] = ()
    scenario_name: str = "paper"


# ---------------------------------------------------------------------------- policies
def _card_mode(path: Path) -> str | None:
    card = path.with_suffix(".json")
    try:
        mode = json.loads(card.read_text(encoding="utf-8")).get("mode")
    except (OSError, ValueError, AttributeError):
        return None
    return mode if mode in AGENTS else None


def _policy_file(text: str) -> Path:
    from explaindrive.agent.checkpoint import policy_file

    path = policy_file(text)
    if not path.is_file():
        raise SpecError(
            f"policy file not found: {path} (POLICY is one of {', '.join(POLICY_NAMES)} "
            "or a policy .pt file / training run directory)"
        )
    return path


def _shipped(name: str, override: str | Path | None) -> Path:
    from explaindrive.agent.controller import shipped_policy_path

    if override is not None:
        return _policy_file(str(override))
    path = shipped_policy_path(name)
    if not path.is_file():
        raise SpecError(
            f"the shipped {name} policy is not installed ({path}); pass a file with "
            f"--{name}-policy PATH, or train one with `explaindrive train --mode {name}`"
        )
    return path


def parse_policy(
    text: str,
    *,
    fast_path: str | Path | None = None,
    comfort_path: str | Path | None = None,
    shield: bool = True,
) -> PolicySpec:
    """Resolve ``fast | comfort | merged | krauss | idm | PATH`` into a :class:`PolicySpec`.

    Args:
        text: the policy name or a policy file / training run directory.
        fast_path: use this file instead of the shipped fast policy.
        comfort_path: use this file instead of the shipped comfort policy.
        shield: agents act through the safety shield (ignored for baselines).

    Raises:
        SpecError: if a policy file is missing.
    """
    name = text.strip()
    key = name.lower()
    if key in BASELINES:
        return PolicySpec(key, "baseline", (), key, Command.FAST.label)
    if key in AGENTS:
        path = _shipped(key, fast_path if key == "fast" else comfort_path)
        return PolicySpec(key, "agent", (str(path),), "agent", key, shield)
    if key == MERGED:
        paths = (_shipped("fast", fast_path), _shipped("comfort", comfort_path))
        return PolicySpec(MERGED, "merged", tuple(str(p) for p in paths), "agent",
                          Command.FAST.label, shield)  # fmt: skip
    path = _policy_file(name)
    stem = path.parent.name if path.stem == "policy" else path.stem
    primary = _card_mode(path) or Command.FAST.label
    return PolicySpec(stem, "agent", (str(path),), "agent", primary, shield)


# ---------------------------------------------------------------------------- grids
def check_schedule(policy: PolicySpec, command: str, schedule: Sequence[tuple[float, str]]) -> None:
    """Reject commands a policy was not trained for (e.g. comfort for the fast agent).

    Raises:
        SpecError: naming the command and the policy.
    """
    allowed = policy.allowed_commands
    for cmd in (command, *(c for _t, c in schedule)):
        if cmd not in allowed:
            raise SpecError(
                f"policy {policy.name!r} drives only under {', '.join(allowed)}; "
                f"got command {cmd!r} (use the merged policy to switch agents)"
            )


def build_grid(
    policy: PolicySpec,
    seeds: Sequence[int],
    levels: Sequence[float],
    *,
    command: str | None = None,
    schedule: Sequence[tuple[float, str]] = (),
    max_steps: int = DEFAULT_MAX_STEPS,
    obs_noise: tuple[float, float] = (0.0, 0.0),
) -> tuple[EpisodeSpec, ...]:
    """Every (traffic level, seed) episode, level-major, in the given order.

    Raises:
        SpecError: on an empty grid, a bad step limit or a command the policy cannot take.
    """
    if not seeds or not levels:
        raise SpecError("the grid is empty: give at least one seed and one traffic level")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps <= 0:
        raise SpecError(f"max_steps must be a positive integer, got {max_steps!r}")
    if max_steps > MAX_STEPS:
        raise SpecError(f"--max-steps {max_steps} is too long; at most {MAX_STEPS} [s]")
    first = command or policy.primary
    sched = tuple((float(t), Command.parse(c).label) for t, c in schedule)
    check_schedule(policy, first, sched)
    return tuple(
        EpisodeSpec(policy, int(seed), float(level), first, sched, max_steps, obs_noise)
        for level in levels
        for seed in seeds
    )


@dataclass(frozen=True, slots=True)
class RunPlan:
    """A named run: a policy under one command schedule over a seed x level grid.

    Attributes:
        name: label in tables and files; the bare policy name only for a run without
            command changes (that is the run the paper's table describes).
        episodes: the grid.
        stop_intervals: stop-command intervals [s], for shading figures.
    """

    name: str
    episodes: tuple[EpisodeSpec, ...]
    stop_intervals: tuple[tuple[float, float | None], ...]


def plan_run(
    policy: PolicySpec,
    seeds: Sequence[int],
    levels: Sequence[float],
    *,
    stop_schedule: str | None = None,
    commands: str | None = None,
    max_steps: int = DEFAULT_MAX_STEPS,
    name: str | None = None,
    obs_noise: tuple[float, float] = (0.0, 0.0),
) -> RunPlan:
    """Build a run from parsed seeds/levels and the schedule texts of the CLI.

    The merged policy without ``commands`` runs the paper's fast -> stop -> comfort episode.

    Raises:
        SpecError: on a bad schedule, both schedules at once, or an empty grid.
    """
    from explaindrive.evaluation.paper import PAPER_MERGED_COMMANDS

    if stop_schedule and commands:
        raise SpecError("give either --stop-schedule or --commands, not both")
    if policy.kind == "merged" and not stop_schedule and not commands:
        commands = PAPER_MERGED_COMMANDS
    first = policy.primary
    schedule: tuple[tuple[float, str], ...] = ()
    intervals: tuple[tuple[float, float | None], ...] = ()
    label = policy.name
    if stop_schedule:
        intervals = parse_stop_schedule(stop_schedule)
        schedule = stops_to_schedule(policy.primary, intervals)
        label = f"{policy.name} + stops"
    elif commands:
        segments = parse_commands(commands)
        first, schedule = segments_to_schedule(segments)
        intervals = tuple((s, e) for c, s, e in segments if c == Command.STOP.label)
        if policy.kind != "merged" or commands != PAPER_MERGED_COMMANDS:
            label = f"{policy.name} ({commands})"
    if obs_noise != (0.0, 0.0):
        label = f"{label}, noise {obs_noise[0]:g} m / {obs_noise[1]:g} m/s"
    episodes = build_grid(policy, seeds, levels, command=first, schedule=schedule,
                          max_steps=max_steps, obs_noise=obs_noise)  # fmt: skip
    return RunPlan(name or label, episodes, intervals)
