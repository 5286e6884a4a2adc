"""Models shipped ready to load by PyPI packages, pinned by SHA-256."""

from __future__ import annotations

import hashlib
import sys
import types
from pathlib import Path

import pytest

from explaindrive.language.packaged import (
    MINILM,
    WHISPER_TINY_EN,
    ModelIntegrityError,
    PackagedModel,
    packaged_model_dir,
)

TOY = PackagedModel(
    "fake_model_pkg", "fake-model-pkg", "model.bin",
    hashlib.sha256(b"weights").hexdigest(), "Toy", "made here",
)  # fmt: skip


@pytest.fixture
def fake_package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    fake = types.ModuleType("fake_model_pkg")
    fake.get_model_path = lambda: str(tmp_path)  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "fake_model_pkg", fake)
    return tmp_path


def test_the_pinned_weights_load(fake_package: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"Toy: model\.bin not found under"):
        packaged_model_dir(TOY)
    (fake_package / "model.bin").write_bytes(b"weights")
    assert packaged_model_dir(TOY) == fake_package


def test_tampered_weights_are_refused_naming_the_package(fake_package: Path) -> None:
    (fake_package / "model.bin").write_bytes(b"weightz")
    with pytest.raises(ModelIntegrityError) as err:
        packaged_model_dir(TOY)
    message = str(err.value)
    assert "from package 'fake-model-pkg' is not the pinned release" in message
    assert hashlib.sha256(b"weightz").hexdigest()[:12] in message
    assert "pip install --force-reinstall fake-model-pkg" in message


def test_the_installed_models_are_the_pinned_ones() -> None:
    # the upstream files' SHA-256 (all-MiniLM-L6-v2 model.safetensors, Whisper tiny.en
    # model.bin in CTranslate2 format)
    assert MINILM.sha256.startswith("53aa5117") and MINILM.sha256.endswith("d9db")
    assert WHISPER_TINY_EN.sha256.startswith("1a5afae0") and WHISPER_TINY_EN.sha256.endswith("6b2a")
    for model in (MINILM, WHISPER_TINY_EN):
        assert (packaged_model_dir(model) / model.weights).is_file()


def test_transcribe_refuses_tampered_weights_in_one_line(
    tmp_path: Path, fake_package: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import wave

    from typer.testing import CliRunner

    from explaindrive.cli.app import app

    (fake_package / "model.bin").write_bytes(b"tampered")
    monkeypatch.setattr("explaindrive.language.speech.transcriber.WHISPER_TINY_EN", TOY)
    clip = tmp_path / "clip.wav"
    with wave.open(str(clip), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(16_000)
        w.writeframes((b"\x00\x10\x00\xf0") * 8000)  # 1 s of a square wave
    result = CliRunner().invoke(app, ["transcribe", str(clip)])
    assert result.exit_code != 0 and "Traceback" not in result.output
    text = " ".join(result.output.split())
    assert "from package 'fake-model-pkg' is not the pinned release" in text
