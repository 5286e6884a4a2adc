"""The encoders on ONNX Runtime: the export matches PyTorch, is cached, and a bad export
leaves nothing behind."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from pydantic import ValidationError

from explaindrive.cache import cache_dir
from explaindrive.language.config import EmbeddedConfig
from explaindrive.language.data import TRAIN_CSV, data_path
from explaindrive.language.intent import onnx_encoder
from explaindrive.language.intent.datasets import load_commands
from explaindrive.language.intent.encoders import SentenceEncoder, check_runtime, minilm_model_dir
from explaindrive.language.intent.onnx_encoder import export_dir, export_onnx, onnx_model_file

LONG = " ".join(["please slow down a little because the road is wet"] * 40)  # > 256 tokens


def test_runtime_names() -> None:
    assert check_runtime("onnx") == "onnx" and check_runtime("torch") == "torch"
    with pytest.raises(ValueError, match="unknown encoder runtime 'tf'"):
        check_runtime("tf")
    with pytest.raises(ValidationError):
        EmbeddedConfig(encoder_runtime="tf")  # type: ignore[arg-type]
    # threads: 2 on ONNX Runtime, 1 on PyTorch, unless configured
    assert SentenceEncoder().threads == 2
    assert SentenceEncoder(runtime="torch").threads == 1
    assert SentenceEncoder(runtime="torch", threads=2).threads == 2


def test_onnx_matches_torch_on_requests_and_overlong_text() -> None:
    onnx_encoder = SentenceEncoder()
    assert onnx_encoder.runtime == "onnx"
    rows = [r for r in load_commands(data_path(TRAIN_CSV)) if r.split == "dev-1"][:40]
    texts = [r.text for r in rows]
    texts += ["", LONG]
    torch_encoder = SentenceEncoder(runtime="torch")
    onnx_emb = onnx_encoder.encode(texts)
    assert float(np.max(np.abs(onnx_emb - torch_encoder.encode(texts)))) < 1e-5
    # one sentence at a time, as in a ride, gives the batch's embeddings
    single = np.vstack([onnx_encoder.encode([t]) for t in texts[:5]])
    assert float(np.max(np.abs(single - onnx_emb[:5]))) < 1e-5
    runner = onnx_encoder._onnx
    assert runner is not None
    prepare = torch_encoder._model.preprocess
    for text in (texts[0], LONG):
        ours = runner.tokens([text])["input_ids"][0].tolist()
        assert ours == prepare([text])["input_ids"][0].tolist()
    assert len(runner.tokens([LONG])["input_ids"][0]) == 256  # truncated like torch


def test_export_is_kept_and_reused(monkeypatch: pytest.MonkeyPatch) -> None:
    SentenceEncoder().load()  # exported on first use (or already in the cache)
    target = export_dir(minilm_model_dir(), cache_dir(), "minilm")
    assert (target / onnx_encoder.ONNX_FILE).is_file()
    assert "max |onnx - torch|" in (target / ".complete").read_text()

    def refuse(*_: object) -> Path:
        raise AssertionError("exported again")

    monkeypatch.setattr(onnx_encoder, "export_onnx", refuse)
    assert onnx_model_file(minilm_model_dir(), cache_dir(), "minilm") == target / "encoder.onnx"


def test_export_folder_follows_label_and_weights(tmp_path: Path) -> None:
    model = tmp_path / "model"
    model.mkdir()
    (model / "model.safetensors").write_bytes(b"0" * 10)
    first = export_dir(model, tmp_path, "minilm")
    assert first.parent == tmp_path / "onnx" and first.name.startswith("minilm-")
    assert export_dir(model, tmp_path, "minilm") == first
    assert export_dir(model, tmp_path, "other") != first
    os.utime(model / "model.safetensors", ns=(1, 1))  # a replaced model is exported afresh
    assert export_dir(model, tmp_path, "minilm") != first


def test_export_that_differs_from_torch_is_refused_and_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(onnx_encoder, "EXPORT_TOLERANCE", -1.0)
    target = tmp_path / "onnx" / "minilm-test"
    with pytest.raises(RuntimeError, match=r"differs from PyTorch.*encoder_runtime: torch"):
        export_onnx(minilm_model_dir(), target)
    assert list((tmp_path / "onnx").iterdir()) == []


def test_a_folder_that_is_not_a_model_is_refused(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="not a sentence-transformers model"):
        export_onnx(tmp_path, tmp_path / "out")
    with pytest.raises(FileNotFoundError, match="model directory not found"):
        SentenceEncoder(tmp_path / "missing").load()


def test_an_exporter_failure_names_the_way_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import torch

    def broken(*_: object, **__: object) -> None:
        raise NotImplementedError("no exporter here")

    monkeypatch.setattr(torch.onnx, "export", broken)
    with pytest.raises(RuntimeError, match=r"NotImplementedError: no exporter here.*torch"):
        export_onnx(minilm_model_dir(), tmp_path / "onnx" / "minilm-test")
    assert list((tmp_path / "onnx").iterdir()) == []
