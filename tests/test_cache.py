"""The per-user cache: where it is, and folders published whole."""

from __future__ import annotations

from pathlib import Path

import pytest

from explaindrive.cache import COMPLETE_MARK, cache_dir, is_complete, publish


def test_cache_dir_precedence(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("EXPLAINDRIVE_CACHE", str(tmp_path / "own"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_dir() == tmp_path / "own"
    monkeypatch.delenv("EXPLAINDRIVE_CACHE")
    assert cache_dir() == tmp_path / "xdg" / "explaindrive"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache_dir() == tmp_path / "home" / ".cache" / "explaindrive"


def _staged(tmp_path: Path, name: str, content: str) -> Path:
    staged = tmp_path / name
    staged.mkdir()
    (staged / "data.txt").write_text(content)
    return staged


def test_publish_marks_and_renames(tmp_path: Path) -> None:
    target = tmp_path / "model"
    assert not is_complete(target)
    assert publish(_staged(tmp_path, ".model-1", "mine"), target, "checked\n") == target
    assert is_complete(target) and (target / COMPLETE_MARK).read_text() == "checked\n"
    assert (target / "data.txt").read_text() == "mine"


def test_a_complete_target_published_first_wins(tmp_path: Path) -> None:
    target = tmp_path / "model"
    publish(_staged(tmp_path, ".model-1", "first"), target)
    assert publish(_staged(tmp_path, ".model-2", "second"), target) == target
    assert (target / "data.txt").read_text() == "first"


def test_an_incomplete_target_is_not_taken_for_done(tmp_path: Path) -> None:
    target = tmp_path / "model"
    target.mkdir()
    (target / "half.bin").write_text("x")  # left by something else, not published
    with pytest.raises(OSError):
        publish(_staged(tmp_path, ".model-1", "mine"), target)
    assert not is_complete(target)
