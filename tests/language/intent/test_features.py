"""Sentence features: the encoder's direct forward pass and the feature layout."""

from __future__ import annotations

import numpy as np

from explaindrive.language.intent.cues import N_CUES
from explaindrive.language.intent.features import (
    HASH_FEATURES,
    FeatureSpec,
    SentenceEncoder,
    features,
)


def test_both_runtimes_match_sentence_transformers(interpreter) -> None:  # type: ignore[no-untyped-def]
    texts = ["could you go a bit faster", "stop", "please take it easy, I'm carrying soup"] * 30
    torch_enc = SentenceEncoder(runtime="torch")
    torch_enc.load()
    expected = torch_enc._model.encode(texts, normalize_embeddings=True, show_progress_bar=False)
    for enc in (interpreter.encoder, torch_enc):  # the ONNX default, then PyTorch
        ours = enc.encode(texts)  # 90 texts: two forward batches, padded differently
        assert ours.shape == (90, 384) and ours.dtype == np.float32
        np.testing.assert_allclose(ours, expected, atol=1e-5)
        np.testing.assert_allclose(np.linalg.norm(ours, axis=1), 1.0, atol=1e-5)
        assert enc.encode([]).shape == (0, 384)


def test_feature_layout(interpreter) -> None:  # type: ignore[no-untyped-def]
    spec = FeatureSpec(ngram_weight=2.0, cue_weight=0.5)
    x = features(interpreter.encoder, ["go faster", "slow down"], spec)
    assert x.shape == (2, 384 + HASH_FEATURES + N_CUES)
    # the n-gram block is l2-normalised, then scaled by its weight
    np.testing.assert_allclose(np.linalg.norm(x[:, 384 : 384 + HASH_FEATURES], axis=1), 2.0)
    # "go faster": one plain fast cue at weight 0.5
    assert x[0, 384 + HASH_FEATURES :].sum() == 0.5
