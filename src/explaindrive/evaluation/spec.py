"""What to evaluate: policies, seeds, traffic levels and command schedules.

Every parser raises :class:`SpecError` (a ``ValueError``) with a message that names the
offending text, so the CLI can print it as is.

Text formats:
    seeds           ``0-4`` or ``0,3,7`` or ``0-4,10`` (integers in [0, 2**31))
    traffic levels  ``0.5,0.75,1.0`` (finite numbers > 0, no duplicates)
    stop schedule   ``60-75,150-165``: stop from 60 s to 75 s and from 150 s to 165 s;
                    the last interval may be open (``150-``: stop until the end)
    commands        ``fast:0-90,stop:90-110,comfort:110-``: contiguous segments starting at
                    0 s, the last one open-ended
"""

from __future__ import annotations

import itertools
import json
import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from explaindrive.commands import COMMAND_LABELS, Command
from explaindrive.limits import MAX_SEEDS, MAX_STEPS
from explaindrive.sim.scenario.limits import validate_seed, validate_traffic_level

BASELINES: tuple[str, ...] = ("krauss", "idm")
AGENTS: tuple[str, ...] = ("fast", "comfort")
MERGED = "merged"
POLICY_NAMES: tuple[str, ...] = (*AGENTS, MERGED, *BASELINES)
DEFAULT_MAX_STEPS = 1000  # [steps of 1 s] episode limit, as in the env's default


class SpecError(ValueError):
    """An invalid seed list, traffic level list, schedule or policy."""


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


# ---------------------------------------------------------------------------- text parsers
def _items(text: str, what: str) -> list[str]:
    if not isinstance(text, str) or not text.strip():
        raise SpecError(f"{what} is empty")
    items = [item.strip() for item in text.split(",")]
    if any(not item for item in items):
        raise SpecError(f"{what} {text!r} has an empty entry (stray comma?)")
    return items


def _seed(token: str, text: str) -> int:
    try:
        value = int(token)
    except ValueError:
        raise SpecError(f"seed {token!r} in {text!r} is not an integer") from None
    try:
        validate_seed(value)
    except ValueError:
        raise SpecError(f"seed {value} in {text!r} is outside [0, 2**31)") from None
    return value


def _check_seed_count(n: int, text: str) -> None:
    if n > MAX_SEEDS:
        raise SpecError(f"seed list {text!r} names {n} or more seeds; at most {MAX_SEEDS} in a run")


def parse_seeds(text: str) -> tuple[int, ...]:
    """Parse ``0-4``, ``0,3,7`` or ``0-4,10`` into distinct seeds, in the given order.

    Raises:
        SpecError: on a non-integer, a negative or too large seed, a reversed range, more
            than :data:`~explaindrive.limits.MAX_SEEDS` seeds (checked before a range is
            expanded) or a duplicate.
    """
    seeds: list[int] = []
    for item in _items(text, "seed list"):
        head, sep, tail = item.partition("-")
        if sep and head.strip():
            lo, hi = _seed(head.strip(), text), _seed(tail.strip(), text)
            if hi < lo:
                raise SpecError(f"seed range {item!r} is reversed (use {hi}-{lo})")
            _check_seed_count(len(seeds) + hi - lo + 1, text)
            seeds.extend(range(lo, hi + 1))
        else:
            _check_seed_count(len(seeds) + 1, text)
            seeds.append(_seed(item, text))
    counts = Counter(seeds)
    dupes = sorted(s for s, n in counts.items() if n > 1)
    if dupes:
        raise SpecError(f"seed list {text!r} repeats seed(s) {dupes}")
    return tuple(seeds)


def parse_levels(text: str) -> tuple[float, ...]:
    """Parse ``0.5,0.75,1.0`` into distinct traffic levels.

    Raises:
        SpecError: on a non-number, a level <= 0 or non-finite, or a duplicate.
    """
    levels: list[float] = []
    for item in _items(text, "traffic level list"):
        try:
            value = float(item)
        except ValueError:
            raise SpecError(f"traffic level {item!r} in {text!r} is not a number") from None
        try:
            levels.append(validate_traffic_level(value))
        except ValueError as exc:
            raise SpecError(f"{exc} (in {text!r})") from None
    dupes = sorted({x for x in levels if levels.count(x) > 1})
    if dupes:
        raise SpecError(f"traffic level list {text!r} repeats level(s) {dupes}")
    return tuple(levels)


def _time(token: str, text: str) -> float:
    try:
        value = float(token)
    except ValueError:
        raise SpecError(f"time {token!r} in {text!r} is not a number of seconds") from None
    if not math.isfinite(value) or value < 0:
        raise SpecError(f"time {token!r} in {text!r} must be a finite number >= 0")
    return value


def _interval(item: str, text: str) -> tuple[float, float | None]:
    head, sep, tail = item.partition("-")
    if not sep or not head.strip():
        raise SpecError(f"interval {item!r} in {text!r} must look like START-END or START-")
    start = _time(head.strip(), text)
    end = _time(tail.strip(), text) if tail.strip() else None
    if end is not None and end <= start:
        raise SpecError(f"interval {item!r} in {text!r} ends before it starts")
    return start, end


def parse_stop_schedule(text: str) -> tuple[tuple[float, float | None], ...]:
    """Parse ``60-75,150-165`` into ordered, non-overlapping stop intervals [s].

    Raises:
        SpecError: on a malformed, reversed, overlapping or unordered interval, or an open
            interval that is not the last one.
    """
    intervals = [_interval(item, text) for item in _items(text, "stop schedule")]
    for (s0, e0), (s1, _e1) in itertools.pairwise(intervals):
        if e0 is None:
            raise SpecError(f"stop schedule {text!r}: only the last interval may be open-ended")
        if s1 < e0:
            raise SpecError(
                f"stop schedule {text!r}: intervals must be in order and must not overlap "
                f"({s0:g}-{e0:g} and one starting at {s1:g})"
            )
    return tuple(intervals)


def parse_commands(text: str) -> tuple[tuple[str, float, float | None], ...]:
    """Parse ``fast:0-90,stop:90-110,comfort:110-`` into ``(command, start_s, end_s)``.

    Raises:
        SpecError: on an unknown command, a gap or overlap between segments, a first segment
            that does not start at 0 s, or a closed last segment.
    """
    segments: list[tuple[str, float, float | None]] = []
    for item in _items(text, "command schedule"):
        name, sep, span = item.partition(":")
        if not sep:
            raise SpecError(
                f"command segment {item!r} in {text!r} must look like COMMAND:START-END"
            )
        try:
            cmd = Command.parse(name).label
        except ValueError as exc:
            raise SpecError(f"{exc} (in {text!r})") from None
        start, end = _interval(span.strip(), text)
        segments.append((cmd, start, end))
    if segments[0][1] != 0.0:
        raise SpecError(f"command schedule {text!r} must start at 0 s (e.g. fast:0-90)")
    for (_c0, _s0, e0), (c1, s1, _e1) in itertools.pairwise(segments):
        if e0 is None or s1 != e0:
            raise SpecError(
                f"command schedule {text!r}: segments must be contiguous; {c1} starts at "
                f"{s1:g} s but the previous segment ends at {'the end' if e0 is None else e0}"
            )
    if segments[-1][2] is not None:
        raise SpecError(
            f"command schedule {text!r}: the last segment must be open-ended "
            f"(e.g. {segments[-1][0]}:{segments[-1][1]:g}-)"
        )
    return tuple(segments)


def stops_to_schedule(
    primary: str, intervals: Sequence[tuple[float, float | None]]
) -> tuple[tuple[float, str], ...]:
    """Command switches of stop ``intervals`` injected into a ``primary`` command."""
    out: list[tuple[float, str]] = []
    for start, end in intervals:
        out.append((start, Command.STOP.label))
        if end is not None:
            out.append((end, primary))
    return tuple(out)


def segments_to_schedule(
    segments: Sequence[tuple[str, float, float | None]],
) -> tuple[str, tuple[tuple[float, str], ...]]:
    """The initial command and the later switches of parsed command segments."""
    return segments[0][0], tuple((start, cmd) for cmd, start, _end in segments[1:])


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
