"""Choosing when LLM-1 answers: the thresholds and the risk-coverage curve.

On the calibration pool (lines the model was not trained on), the STOP threshold is the
lowest that reads none of the lines asking for no command as STOP: everyday text outside
the pool is read as STOP several times as often as the pool's lines (docs/language.md), so
the target of at most 0.1 % on everyday talk leaves no false STOP on the pool (a missed STOP
request has to be said again; the plainest are heard by STOP's explicit path whatever the
threshold); the command threshold is the lowest that gives at most
:data:`MAX_FALSE_COMMAND` of the lines that ask for no command a command.

Below the STOP threshold the car asks back: a line whose most probable reading is STOP is
asked about ("You want me to stop, is this correct?") from the lowest threshold that asks
about at most :data:`MAX_STOP_ASKED` of the lines without a command. A STOP request said
tersely, crossly or misspelled is then heard at the cost of one question, and everyday
talk is left alone: with commands given to at most 2 % of it and questions asked of at
most 0.5 %, the target of 97 % left alone holds on the pool.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from explaindrive.commands import COMMAND_LABELS
from explaindrive.language.intent.model import STOP, IntentModel, Thresholds

MAX_FALSE_COMMAND = 0.02
"""Share of lines without a command that may be given one (the target is 0.03)."""
MAX_STOP_ASKED = 0.005
"""Share of lines without a command that the car may ask whether to stop."""
GRID = np.round(np.arange(0.30, 0.991, 0.01), 2)


@dataclass(frozen=True)
class CurvePoint:
    """The calibration pool's figures at one command threshold.

    Attributes:
        threshold: the command threshold.
        coverage: share of the command requests given a command.
        risk: share of the lines given a command that were given the wrong one (another
            command, or one where none was asked).
        false_command: share of the lines without a command that were given one.
    """

    threshold: float
    coverage: float
    risk: float
    false_command: float


def readings(model: IntentModel, p: NDArray[np.floating], t: Thresholds) -> list[str]:
    """The reading of each probability row under thresholds ``t``."""
    return [model.decide(row, t).reading for row in p]


def curve(
    model: IntentModel, p: NDArray[np.floating], labels: list[str], stop: float
) -> list[CurvePoint]:
    """The risk-coverage curve over :data:`GRID` at STOP threshold ``stop``."""
    asked = np.array([lab in COMMAND_LABELS for lab in labels])
    points = []
    for t in GRID:
        got = readings(model, p, Thresholds(float(t), stop))
        given = np.array([g in COMMAND_LABELS for g in got])
        wrong = np.array([g != lab for g, lab in zip(got, labels, strict=True)]) & given
        points.append(
            CurvePoint(
                float(t),
                float(given[asked].mean()) if asked.any() else 0.0,
                float(wrong.sum() / max(1, given.sum())),
                float(given[~asked].mean()) if (~asked).any() else 0.0,
            )
        )
    return points


def stop_threshold(p_negative: NDArray[np.floating]) -> float:
    """The lowest threshold of :data:`GRID` that reads none of ``p_negative`` as STOP (if
    none does, the highest of the grid).

    Args:
        p_negative: STOP's probability on the lines that ask for no command.
    """
    top = float(np.max(p_negative)) if len(p_negative) else 0.0
    return next((float(t) for t in GRID if t > top), float(GRID[-1]))


def ask_stop_threshold(
    model: IntentModel, p: NDArray[np.floating], negative: NDArray[np.bool_], stop: float
) -> float:
    """The lowest threshold of :data:`GRID` (below ``stop``) that asks about at most
    :data:`MAX_STOP_ASKED` of the lines without a command (``negative``); ``stop`` itself
    (no band) when none does. Which lines fall in the band is the model's decision rule's
    (:meth:`IntentModel.decide` with the band open down to 0).

    Args:
        model: the model whose decision rule reads the rows.
        p: the readings' probabilities, one row per line of the pool.
        negative: which lines ask for no command.
        stop: the STOP threshold.
    """
    p = np.asarray(p)
    open_band = Thresholds(float(GRID[-1]), stop, 0.0)
    band = np.array([model.decide(row, open_band).ask_stop for row in p], dtype=bool)
    asked = band & negative
    n = max(1, int(negative.sum()))
    return next(
        (
            float(t)
            for t in GRID
            if t < stop and (asked & (p[:, STOP] >= t)).sum() / n <= MAX_STOP_ASKED
        ),
        stop,
    )


def choose_thresholds(
    model: IntentModel, p: NDArray[np.floating], labels: list[str]
) -> tuple[Thresholds, str]:
    """The thresholds (see the module docstring) and a printable report with the curve."""
    negative = np.array([lab not in COMMAND_LABELS for lab in labels])
    stop = stop_threshold(np.asarray(p)[negative, STOP])
    ask = ask_stop_threshold(model, p, negative, stop)
    points = curve(model, p, labels, stop)
    command = next(
        (pt.threshold for pt in points if pt.false_command <= MAX_FALSE_COMMAND),
        float(GRID[-1]),
    )
    lines = [
        f"calibration pool: {len(labels)} lines, {int(negative.sum())} without a command",
        f"STOP threshold {stop:.2f}, asked about from {ask:.2f}, command threshold {command:.2f}",
        "threshold  coverage  risk    false-command",
    ]
    lines += [
        f"{pt.threshold:9.2f}  {pt.coverage:8.3f}  {pt.risk:6.3f}  {pt.false_command:6.3f}"
        for pt in points
        if round(pt.threshold * 100) % 5 == 0
    ]
    return Thresholds(command, stop, ask), "\n".join(lines)
