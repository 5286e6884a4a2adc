"""LLM-1 over all-mpnet-base-v2 alone (``intent_model: mpnet``)."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.commands import Command
from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter
from explaindrive.language.config import EmbeddedConfig
from explaindrive.language.datasets import DEV_SPLITS, INTENT_LABELS, data_path, load_commands
from explaindrive.language.features import features
from explaindrive.language.intent_classifier import decide_rows
from explaindrive.ride.script import default_script_path, load_script


@pytest.fixture(scope="module")
def mpnet() -> EmbeddedIntentInterpreter:
    it = EmbeddedIntentInterpreter(EmbeddedConfig(intent_model="mpnet"))
    it.load()
    return it


def test_encoder_is_mpnet(mpnet: EmbeddedIntentInterpreter) -> None:
    emb = mpnet.encoder.encode(["could you go a bit faster", "stop"])
    assert emb.shape == (2, 768)
    np.testing.assert_allclose(np.linalg.norm(emb, axis=1), 1.0, atol=1e-5)
    assert mpnet.classifier.spec.encoder == "mpnet"


def test_default_ride_lines(mpnet: EmbeddedIntentInterpreter) -> None:
    said = [line.say for line in load_script(default_script_path())]
    got = [mpnet.interpret(text).intent for text in said if text is not None]
    assert got == [Command.FAST, Command.STOP, Command.COMFORT]


def test_stop_recall_on_every_dev_split(mpnet: EmbeddedIntentInterpreter) -> None:
    stops = [
        r.text for name in DEV_SPLITS for r in load_commands(data_path(name)) if r.label == "stop"
    ]
    clf = mpnet.classifier
    p = clf.proba(features(mpnet.encoder, stops, clf.spec))  # one batched pass
    pred = decide_rows(p, clf.stop_threshold, clf.none_margin)
    missed = [t for t, k in zip(stops, pred, strict=True) if INTENT_LABELS[k] != "stop"]
    assert len(stops) > 450 and missed == []
