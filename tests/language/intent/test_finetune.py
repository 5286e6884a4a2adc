"""LLM-1's fine-tuning: the schedule, each epoch's lines, checkpoints and resuming."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from explaindrive.language.intent import finetune
from explaindrive.language.intent.corpus import Example
from explaindrive.language.intent.finetune import FinetuneConfig, _epoch_lines, _lr_factor


def test_the_learning_rate_warms_up_over_a_twentieth_then_decays_to_zero() -> None:
    # 100 steps: warm-up over 5, then linear from 1 at step 5 to 0 at step 100
    assert [_lr_factor(s, 100) for s in (0, 1, 4)] == pytest.approx([0.2, 0.4, 1.0])
    assert _lr_factor(5, 100) == pytest.approx(1.0)
    assert _lr_factor(52, 100) == pytest.approx(48 / 95)
    assert _lr_factor(100, 100) == 0.0


def test_an_epoch_sees_every_labelled_line_twice_and_a_fresh_draw_of_everyday_lines() -> None:
    labelled = [Example(f"l{i}", "fast", "x") for i in range(3)]
    everyday = [Example(f"e{i}", "none", "y") for i in range(10)]
    cfg = FinetuneConfig(everyday_per_epoch=4, address_share=0.0)
    first, second = (_epoch_lines(labelled, everyday, cfg, epoch) for epoch in (0, 1))
    assert len(first) == 3 * 2 + 4
    assert sorted(e.text for e in first if e.label == "fast") == [
        "l0",
        "l0",
        "l1",
        "l1",
        "l2",
        "l2",
    ]
    drawn = [{e.text for e in lines if e.label == "none"} for lines in (first, second)]
    assert len(drawn[0]) == 4 and drawn[0] != drawn[1]


def test_addressed_lines_keep_their_label_and_everyday_lines_stay_as_drawn() -> None:
    labelled = [Example("Stop the car.", "stop", "x"), Example("Faster!", "fast", "x")]
    everyday = [Example(f"e{i}", "none", "y") for i in range(4)]
    cfg = FinetuneConfig(everyday_per_epoch=4, address_share=1.0, slip_share=0.0)
    lines = _epoch_lines(labelled, everyday, cfg, 0)
    seen = [e for e in lines if e.label != "none"]
    assert len(seen) == 4 and all(", " in e.text for e in seen)
    assert {e.label for e in seen if "top the car" in e.text} == {"stop"}
    assert sorted(e.text for e in lines if e.label == "none") == ["e0", "e1", "e2", "e3"]


@pytest.mark.models
def test_a_run_checkpoints_each_epoch_and_resumes_after_the_last(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    lines = [Example("drive faster please", "fast", "t"), Example("nice weather", "none", "t")]
    monkeypatch.setattr(finetune, "training_pool", lambda: (lines, lines))
    cfg = FinetuneConfig(epochs=1, everyday_per_epoch=2, batch_size=2, threads=1)
    reader, cpu = finetune.train(tmp_path, cfg)
    assert (tmp_path / finetune.CHECKPOINT).is_file() and cpu > 0
    assert not (tmp_path / (finetune.CHECKPOINT + ".tmp")).exists()
    before = reader.head.weight.detach().numpy().copy()
    again, cpu_again = finetune.train(tmp_path, cfg, resume=True)  # nothing left to do
    assert cpu_again == pytest.approx(cpu)
    np.testing.assert_array_equal(again.head.weight.detach().numpy(), before)
    with pytest.raises(FileNotFoundError, match="no checkpoint"):
        finetune.train(tmp_path / "empty", cfg, resume=True)
