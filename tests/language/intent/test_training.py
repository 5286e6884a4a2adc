"""LLM-1 model building: STOP threshold tuning and leave-one-split-out selection."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.language.intent.features import FeatureSpec
from explaindrive.language.intent.training import (
    Encoded,
    Hyper,
    held_out_proba,
    select,
    selection_cost,
    tune_none_margin,
    tune_stop_threshold,
)


def test_stop_threshold_minimises_weighted_cost() -> None:
    # STOP rows at 0.9, 0.35, 0.2; other rows at 0.15 and 0.4. With a miss costing 5:
    # t <= 0.15 -> 2 false alarms (cost 2); 0.15 < t <= 0.20 -> 1 false alarm (cost 1);
    # 0.20 < t <= 0.35 -> one miss + one false alarm (cost 6). Lowest best t: 0.16.
    p = np.array([0.9, 0.35, 0.2, 0.15, 0.4])
    is_stop = np.array([True, True, True, False, False])
    assert tune_stop_threshold(p, is_stop) == pytest.approx(0.16)
    # separable: the lowest threshold above the non-STOP row at 0.2 costs nothing
    assert tune_stop_threshold(np.array([0.3, 0.8, 0.2]), np.array([True, True, False])) == (
        pytest.approx(0.21)
    )


def test_selection_cost_weighs_a_missed_stop_like_the_threshold() -> None:
    # labels: 0 fast, 1 comfort, 2 stop, 3 none
    y = np.array([0, 1, 2, 2, 3, 1])
    # one comfort read as fast, one STOP missed (read as comfort): 2 errors, the miss
    # weighing 5 -> 1 + 5 = 6
    assert selection_cost(np.array([0, 0, 2, 1, 3, 1]), y) == pytest.approx(6.0)
    # three errors, none of them a missed STOP (one false STOP, one dropped command, one
    # off-topic request answered) -> 3: preferred to the candidate above
    assert selection_cost(np.array([0, 2, 2, 2, 1, 3]), y) == pytest.approx(3.0)
    assert selection_cost(y, y) == 0.0


def test_none_margin_weighs_dropped_commands_double() -> None:
    # none leads the best command by 0.27 (a fast request), 0.12 (a fast request), 0.22
    # and 0.33 (two off-topic requests). Cost = 2 * dropped commands + answered off-topic:
    # m < 0.12: 2 * 2 = 4; [0.12, 0.22): 2; [0.22, 0.27): 2 + 1 = 3; [0.27, 0.33): 0 + 1 = 1;
    # m >= 0.33: 2. On the 0.05 grid the best margin is 0.30.
    p = np.array(
        [
            [0.28, 0.10, 0.07, 0.55],
            [0.38, 0.05, 0.07, 0.50],
            [0.28, 0.10, 0.12, 0.50],
            [0.22, 0.10, 0.13, 0.55],
        ]
    )
    y = np.array([0, 0, 3, 3])
    assert tune_none_margin(p, y, stop_threshold=0.5) == pytest.approx(0.3)


def _split(texts: list[str], labels: list[int], seed: int) -> Encoded:
    rng = np.random.default_rng(seed)
    centres = np.eye(4, 8, dtype=np.float32)
    emb = centres[labels] + 0.3 * rng.standard_normal((len(labels), 8)).astype(np.float32)
    emb /= np.linalg.norm(emb, axis=1, keepdims=True)
    return Encoded(texts, np.array(labels, dtype=np.int64), emb)


WORDS = ("faster please", "gently please", "stop here", "nice weather")


def toy_encoded(seed: int, n: int = 12) -> Encoded:
    """``n`` toy requests cycling through the four labels, embedded near one centre each."""
    labels = [i % 4 for i in range(n)]
    return _split([f"{WORDS[k]} {i}" for i, k in enumerate(labels)], labels, seed)


def test_held_out_probabilities_never_see_their_split() -> None:
    train, devs = toy_encoded(0, 24), [toy_encoded(1), toy_encoded(2), toy_encoded(3)]
    spec, hyper = FeatureSpec(), Hyper(c=10.0, lr_weight=1.0)
    p = held_out_proba(train, devs, spec, 10.0, hyper)
    assert p.shape == (36, 4)
    np.testing.assert_allclose(p.sum(axis=1), 1.0, atol=1e-9)
    # relabelling split 0 changes the predictions of splits 1 and 2 (it is in their
    # training data) but not those of split 0 itself
    flipped = Encoded(devs[0].texts, (devs[0].y + 1) % 4, devs[0].emb)
    q = held_out_proba(train, [flipped, devs[1], devs[2]], spec, 10.0, hyper)
    np.testing.assert_allclose(q[:12], p[:12])
    assert not np.allclose(q[12:], p[12:])


def test_select_returns_a_grid_point_and_its_held_out_figures() -> None:
    train, devs = toy_encoded(0, 24), [toy_encoded(1), toy_encoded(2)]
    grid = {"c": (1.0, 10.0), "ngram_weight": (1.0,), "cue_weight": (0.0,), "lr_weight": (0.5, 1.0)}
    sel = select(train, devs, grid)
    assert sel.hyper.c in grid["c"] and sel.hyper.lr_weight in grid["lr_weight"]
    # the toy classes are well separated: every held-out request is right
    assert sel.accuracy == pytest.approx(1.0)
    assert sel.stop_recall == pytest.approx(1.0) and sel.false_stops == 0
