"""The two shipped LLM-1 models: MiniLM (the default) and mpnet."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter
from explaindrive.language.datasets import DEV_SPLITS, INTENT_LABELS, data_path, load_commands
from explaindrive.language.features import features
from explaindrive.language.intent_classifier import decide_rows
from explaindrive.ride.script import default_script_path, load_script

DIMENSIONS = {"mpnet": 768, "minilm": 384}


@pytest.fixture(params=["interpreter", "mpnet"])
def model(request: pytest.FixtureRequest) -> EmbeddedIntentInterpreter:
    """Each shipped model in turn (the session fixtures of conftest)."""
    it: EmbeddedIntentInterpreter = request.getfixturevalue(request.param)
    return it


def test_default_is_minilm(interpreter: EmbeddedIntentInterpreter) -> None:
    assert interpreter.encoder.name == "minilm" and interpreter.classifier.spec.encoder == "minilm"


def test_encoder_and_weights_match(model: EmbeddedIntentInterpreter) -> None:
    name = model.encoder.name
    emb = model.encoder.encode(["could you go a bit faster", "stop"])
    assert emb.shape == (2, DIMENSIONS[name])
    np.testing.assert_allclose(np.linalg.norm(emb, axis=1), 1.0, atol=1e-5)
    assert model.classifier.spec.encoder == name
    assert model.classifier.ref_embeddings.shape[1] == DIMENSIONS[name]


def test_default_ride_lines(model: EmbeddedIntentInterpreter) -> None:
    said = [line.say for line in load_script(default_script_path())]
    got = [model.interpret(text).intent for text in said if text is not None]
    assert got == [Command.FAST, Command.STOP, Command.COMFORT]


def test_stop_recall_on_every_dev_split(model: EmbeddedIntentInterpreter) -> None:
    stops = [
        r.text for name in DEV_SPLITS for r in load_commands(data_path(name)) if r.label == "stop"
    ]
    clf = model.classifier
    p = clf.proba(features(model.encoder, stops, clf.spec))  # one batched pass
    pred = decide_rows(p, clf.stop_threshold, clf.none_margin)
    missed = [t for t, k in zip(stops, pred, strict=True) if INTENT_LABELS[k] != "stop"]
    assert len(stops) > 450 and missed == []
