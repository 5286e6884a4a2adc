"""The shipped LLM-1 model over all-MiniLM-L6-v2."""

from __future__ import annotations

import numpy as np

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter
from explaindrive.language.data import TRAIN_CSV, data_path
from explaindrive.language.intent.classifier import decide_rows
from explaindrive.language.intent.datasets import INTENT_LABELS, load_commands, training_splits
from explaindrive.language.intent.features import features
from explaindrive.ride.script import default_script_path, load_script

DIMENSION = 384  # all-MiniLM-L6-v2


def test_encoder_and_weights_match(interpreter: EmbeddedIntentInterpreter) -> None:
    emb = interpreter.encoder.encode(["could you go a bit faster", "stop"])
    assert emb.shape == (2, DIMENSION)
    np.testing.assert_allclose(np.linalg.norm(emb, axis=1), 1.0, atol=1e-5)
    assert interpreter.classifier.spec.encoder == "minilm"
    assert interpreter.classifier.ref_embeddings.shape[1] == DIMENSION


def test_default_ride_lines(interpreter: EmbeddedIntentInterpreter) -> None:
    said = [line.say for line in load_script(default_script_path())]
    got = [interpreter.interpret(text).intent for text in said if text is not None]
    assert got == [Command.FAST, Command.STOP, Command.COMFORT]


def test_stop_recall_on_every_dev_split(interpreter: EmbeddedIntentInterpreter) -> None:
    _, devs = training_splits(load_commands(data_path(TRAIN_CSV)))
    stops = [r.text for dev in devs for r in dev if r.label == "stop"]
    clf = interpreter.classifier
    p = clf.proba(features(interpreter.encoder, stops, clf.spec))  # one batched pass
    pred = decide_rows(p, clf.stop_threshold, clf.none_margin)
    missed = [t for t, k in zip(stops, pred, strict=True) if INTENT_LABELS[k] != "stop"]
    assert len(stops) > 450 and missed == []
