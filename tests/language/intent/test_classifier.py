"""The LLM-1 classifier at run time: the decision rule and the weights file."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from explaindrive.language.intent.classifier import IntentClassifier, decide_rows
from explaindrive.language.intent.training import Encoded, fit_final, select
from tests.language.intent.test_training import toy_encoded


def test_decision_rule() -> None:
    p = np.array(
        [
            [0.30, 0.10, 0.25, 0.35],  # STOP reaches 0.2; none leads the best command by 0.05
            [0.30, 0.10, 0.05, 0.55],  # none leads the best command by 0.25
            [0.40, 0.05, 0.05, 0.50],  # none leads by 0.10
        ]
    )
    # labels: 0 fast, 1 comfort, 2 stop, 3 none
    assert decide_rows(p, 0.2, 0.0).tolist() == [2, 3, 3]
    assert decide_rows(p, 0.3, 0.0).tolist() == [3, 3, 3]
    assert decide_rows(p, 0.3, 0.15).tolist() == [0, 3, 0]  # leads up to 0.15: a command
    assert decide_rows(p, 0.3, 0.3).tolist() == [0, 0, 0]


def test_weights_round_trip_and_remember_their_encoder(tmp_path) -> None:  # type: ignore[no-untyped-def]
    train, devs = toy_encoded(0, 24), [toy_encoded(1), toy_encoded(2)]
    grid = {"c": (10.0,), "ngram_weight": (1.0,), "cue_weight": (0.0,), "lr_weight": (0.5,)}
    clf = fit_final(train, devs, select(train, devs, grid))
    path = tmp_path / "clf.npz"
    clf.save(path)
    back = IntentClassifier.load(path)
    assert back.spec == clf.spec and back.spec.encoder == "minilm"
    np.testing.assert_array_equal(back.coef, clf.coef)
    x = Encoded.concat(devs).features(clf.spec)
    np.testing.assert_allclose(back.proba(x), clf.proba(x), atol=1e-3)  # float16 references
    dataclasses.replace(clf, spec=dataclasses.replace(clf.spec, encoder="bert")).save(path)
    with pytest.raises(ValueError, match="built over the 'bert' encoder's embeddings"):
        IntentClassifier.load(path)
    (tmp_path / "junk.npz").write_bytes(b"not numpy")
    with pytest.raises(ValueError, match="not a valid intent classifier file"):
        IntentClassifier.load(tmp_path / "junk.npz")
