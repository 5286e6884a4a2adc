"""The shipped LLM-1: all-MiniLM-L6-v2 with its adapters, the reading head, the thresholds."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter
from explaindrive.language.intent.corpus import calibration_pool
from explaindrive.language.intent.model import READINGS
from explaindrive.ride.script import default_script_path, load_script

DIMENSION = 384  # all-MiniLM-L6-v2

pytestmark = pytest.mark.models


def test_the_fine_tuned_encoder_gives_unit_embeddings(
    interpreter: EmbeddedIntentInterpreter,
) -> None:
    emb = interpreter.reader.embed(["could you go a bit faster", "stop"])
    assert emb.shape == (2, DIMENSION)
    np.testing.assert_allclose(np.linalg.norm(emb, axis=1), 1.0, atol=1e-5)
    assert interpreter.reader.model.head_w.shape == (len(READINGS), DIMENSION)


def test_default_ride_lines(interpreter: EmbeddedIntentInterpreter) -> None:
    said = [line.say for line in load_script(default_script_path())]
    got = [interpreter.interpret(text) for text in said if text is not None]
    assert [r.intent for r in got] == [Command.FAST, None, Command.STOP, Command.COMFORT]
    assert [r.reading for r in got] == ["fast", "why", "stop", "comfort"]


def test_on_the_calibration_pool_stops_are_heard_and_two_other_lines_are_stops(
    interpreter: EmbeddedIntentInterpreter,
) -> None:
    pool = calibration_pool()
    readings = interpreter.reader.read([e.text for e in pool])
    stops = [r.reading == "stop" for e, r in zip(pool, readings, strict=True) if e.label == "stop"]
    false_stops = {
        e.text
        for e, r in zip(pool, readings, strict=True)
        if e.label not in ("fast", "comfort", "stop") and r.reading == "stop"
    }
    negatives = sum(e.label not in ("fast", "comfort", "stop") for e in pool)
    # no threshold of the grid reads none of the 4,272 lines without a command as STOP, so
    # the calibration took its highest, 0.99: 148 of the 169 STOP requests are heard (a
    # share of 0.876), and two everyday lines labelled "no command" are read as STOP, one
    # by the model (p = 1.0), one by STOP's path ("pull up")
    assert interpreter.reader.model.thresholds.stop == 0.99
    assert len(stops) == 169 and sum(stops) >= 148
    assert negatives == 4272
    assert false_stops == {"Please, stop already.", "Please pull up to the service window, please."}
