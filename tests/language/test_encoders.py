"""Sentence-encoder registry: names, and joining a model zip split over packages."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from explaindrive.language import encoders
from explaindrive.language.encoders import (
    assemble_split_zip,
    check_encoder,
    check_installed,
    mpnet_model_dir,
    mpnet_part_files,
)

FILES = {
    "config.json": b'{"model_type": "toy"}',
    "modules.json": b"[]",
    "model.safetensors": bytes(range(256)) * 40,
    "tokenizer.json": b"{}",
    "1_Pooling/config.json": b'{"pooling_mode_mean_tokens": true}',
    "desktop.ini": b"[.ShellClassInfo]",
}


def _split_zip(tmp_path: Path, members: dict[str, bytes], n_parts: int = 3) -> list[Path]:
    whole = tmp_path / "whole.zip"
    with zipfile.ZipFile(whole, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)
    data = whole.read_bytes()
    step = -(-len(data) // n_parts)
    parts = []
    for k in range(n_parts):
        part = tmp_path / f"toy.zip.{k + 1:03d}"
        part.write_bytes(data[k * step : (k + 1) * step])
        parts.append(part)
    return parts


def test_encoder_names() -> None:
    assert check_encoder("minilm") == "minilm" and check_encoder("mpnet") == "mpnet"
    with pytest.raises(ValueError, match="unknown sentence encoder 'bert'"):
        check_encoder("bert")


def test_split_zip_is_joined_and_extracted(tmp_path: Path) -> None:
    parts = _split_zip(tmp_path, {f"toy/{k}": v for k, v in FILES.items()})
    target = tmp_path / "cache" / "toy"
    assert assemble_split_zip(parts, target, "toy") == target
    for name, data in FILES.items():
        if name != "desktop.ini":
            assert (target / name).read_bytes() == data
    assert not (target / "desktop.ini").exists()
    assert (target / ".complete").is_file()
    # nothing else is left next to the model (the joined zip and staging folder are gone)
    assert [p.name for p in target.parent.iterdir()] == ["toy"]


def test_a_member_outside_the_model_folder_is_refused(tmp_path: Path) -> None:
    parts = _split_zip(tmp_path, {"toy/config.json": b"{}", "toy/../../evil.txt": b"x"})
    target = tmp_path / "cache" / "toy"
    with pytest.raises(ValueError, match="unexpected member"):
        assemble_split_zip(parts, target, "toy")
    assert not target.exists() and not (tmp_path / "evil.txt").exists()


def test_parts_that_are_not_a_zip_or_lack_model_files(tmp_path: Path) -> None:
    junk = tmp_path / "junk.001"
    junk.write_bytes(b"not a zip at all")
    with pytest.raises(ValueError, match="not a zip archive"):
        assemble_split_zip([junk], tmp_path / "cache" / "toy", "toy")
    parts = _split_zip(tmp_path, {"toy/config.json": b"{}"})
    with pytest.raises(ValueError, match=r"lacks modules\.json, model\.safetensors"):
        assemble_split_zip(parts, tmp_path / "cache" / "toy", "toy")
    assert not (tmp_path / "cache" / "toy").exists()


def test_a_complete_cache_is_used_without_the_parts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    done = tmp_path / "models" / "all-mpnet-base-v2"
    done.mkdir(parents=True)
    (done / ".complete").write_text("ok\n")

    def no_parts() -> list[Path]:
        raise AssertionError("the parts must not be read again")

    monkeypatch.setattr(encoders, "mpnet_part_files", no_parts)
    assert mpnet_model_dir(tmp_path) == done
    monkeypatch.setenv("EXPLAINDRIVE_CACHE", str(tmp_path))
    assert mpnet_model_dir() == done
    assert check_installed("mpnet") == "mpnet"  # extracted once: the parts are not needed


@pytest.mark.usefixtures("without_mpnet")
def test_missing_part_package_names_the_extra() -> None:
    extra = r"part-001.*pip install -e '\.\[mpnet\]'"
    with pytest.raises(FileNotFoundError, match=extra):
        mpnet_part_files()
    with pytest.raises(FileNotFoundError, match=extra):
        check_installed("mpnet")
    assert check_installed("minilm") == "minilm"  # a required dependency
