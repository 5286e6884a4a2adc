"""The text formats of a grid and its command schedules, and their parsers.

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
import math
from collections import Counter
from collections.abc import Sequence

from explaindrive.commands import Command
from explaindrive.limits import MAX_SEEDS
from explaindrive.sim.scenario.limits import validate_seed, validate_traffic_level


class SpecError(ValueError):
    """An invalid seed list, traffic level list, schedule or policy."""


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
