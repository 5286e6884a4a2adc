"""The sentence encoder: its one name and the check that it is installed."""

from __future__ import annotations

import pytest

from explaindrive.language.encoders import ENCODER, check_encoder, check_installed


def test_the_only_encoder_name_is_accepted() -> None:
    assert ENCODER == "minilm" and check_encoder("minilm") == "minilm"
    with pytest.raises(ValueError, match="unknown sentence encoder 'bert'"):
        check_encoder("bert")


def test_the_packaged_encoder_is_installed() -> None:
    assert check_installed() == "minilm"
    with pytest.raises(ValueError, match="unknown sentence encoder 'bert'"):
        check_installed("bert")
