"""Models shipped ready to load by PyPI packages."""

from __future__ import annotations

import sys
import types
from pathlib import Path

import pytest

from explaindrive.language.packaged import packaged_model_dir


def test_marker_file_decides(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fake = types.ModuleType("fake_model_pkg")
    fake.get_model_path = lambda: str(tmp_path)  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "fake_model_pkg", fake)
    with pytest.raises(FileNotFoundError, match=r"Toy: model\.bin not found under"):
        packaged_model_dir("fake_model_pkg", "fake-model-pkg", "model.bin", "Toy")
    (tmp_path / "model.bin").write_bytes(b"\0")
    assert packaged_model_dir("fake_model_pkg", "fake-model-pkg", "model.bin", "Toy") == tmp_path
