"""The sentence encoders of LLM-1 on ONNX Runtime.

A sentence-transformers model (transformer, mean pooling, normalisation) is exported once
to ONNX into the cache directory and then run by ONNX Runtime, about twice as fast as
PyTorch for the single short sentences of a ride. The embeddings are the same
as PyTorch's to float rounding (the export is checked against PyTorch before it is kept),
so the classifier weights serve both runtimes.
"""

from __future__ import annotations

import hashlib
import json
import logging
import tempfile
import threading
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from explaindrive.cache import is_complete, publish

log = logging.getLogger(__name__)

ONNX_FILE = "encoder.onnx"
EXPORT_VERSION = 1  # bump when the exported graph changes, so old exports are redone
EXPORT_TOLERANCE = 1e-4  # largest |ONNX - PyTorch| embedding component accepted
_PROBES = (
    "Please drive faster, I am late for my meeting.",
    "stop",
    "Could you take the next corner a little more gently? My coffee is about to spill.",
)


def export_dir(model_dir: Path, root: Path, label: str) -> Path:
    """Where the export of ``model_dir`` lives under cache ``root``: ``onnx/<label>-<digest>``.

    The digest covers the model's location, weights size and time, so a changed model is
    exported afresh.
    """
    model_dir = Path(model_dir).resolve()
    weights = model_dir / "model.safetensors"
    stat = weights.stat() if weights.is_file() else None
    key = f"{model_dir}|{stat.st_size if stat else 0}|{stat.st_mtime_ns if stat else 0}"
    digest = hashlib.sha1(f"{key}|v{EXPORT_VERSION}".encode()).hexdigest()[:10]
    return root / "onnx" / f"{label}-{digest}"


def onnx_model_file(model_dir: Path, root: Path, label: str) -> Path:
    """The ONNX export of ``model_dir`` under cache ``root`` (:func:`export_dir`), made on
    first use.

    Raises:
        FileNotFoundError: if ``model_dir`` is not a sentence-transformers model.
        RuntimeError: if the export fails or does not reproduce PyTorch's embeddings.
    """
    target = export_dir(model_dir, root, label)
    if is_complete(target):
        return target / ONNX_FILE
    return export_onnx(Path(model_dir), target) / ONNX_FILE


def export_onnx(model_dir: Path, target: Path) -> Path:
    """Export the sentence-transformers model in ``model_dir`` to ``target/encoder.onnx``.

    The export happens in a temporary folder next to ``target`` and is renamed into place
    only after its embeddings of a few probe sentences match PyTorch's, so a killed run or
    a bad export leaves nothing behind; another process that finished first wins.

    Raises:
        FileNotFoundError: if ``model_dir`` is not a sentence-transformers model.
        RuntimeError: if the export fails or does not reproduce PyTorch's embeddings.
    """
    if not (model_dir / "modules.json").is_file():
        raise FileNotFoundError(f"not a sentence-transformers model directory: {model_dir}")
    log.info("exporting %s to ONNX (once) into %s", model_dir, target)
    module, probe = _embedding_module(model_dir)
    expected = _torch_embeddings(module, probe)
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=f".{target.name}-") as tmp:
        staged = Path(tmp) / target.name
        staged.mkdir()
        _write_onnx(module, probe, staged / ONNX_FILE, model_dir)
        worst = _export_error(staged / ONNX_FILE, model_dir, expected)
        return publish(staged, target, f"max |onnx - torch| = {worst:.3e}\n")


def _embedding_module(model_dir: Path) -> tuple[Any, tuple[Any, Any]]:
    """The model as one PyTorch module from token ids and attention mask to unit-norm
    embeddings, and those inputs for the probe sentences."""
    import torch
    from sentence_transformers import SentenceTransformer

    model = SentenceTransformer(str(model_dir), device="cpu", local_files_only=True).eval()

    class _Embed(torch.nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.model = model

        def forward(self, input_ids: Any, attention_mask: Any) -> Any:
            out = self.model({"input_ids": input_ids, "attention_mask": attention_mask})
            return torch.nn.functional.normalize(out["sentence_embedding"], dim=-1)

    prepare = getattr(model, "preprocess", None) or model.tokenize
    probe = prepare(list(_PROBES))
    return _Embed(), (probe["input_ids"], probe["attention_mask"])


def _torch_embeddings(module: Any, probe: tuple[Any, Any]) -> NDArray[np.float32]:
    """PyTorch's embeddings of the probe sentences, which the export must reproduce."""
    import torch

    with torch.inference_mode():
        return np.asarray(module(*probe).numpy(), dtype=np.float32)


def _write_onnx(module: Any, probe: tuple[Any, Any], onnx_file: Path, model_dir: Path) -> None:
    """Trace ``module`` on the probe inputs into ``onnx_file``, batch and length left free.

    Raises:
        RuntimeError: if the exporter fails.
    """
    import torch

    try:
        with warnings.catch_warnings():  # tracer notes on branches fixed for this model
            warnings.simplefilter("ignore")
            torch.onnx.export(
                module,
                probe,
                str(onnx_file),
                input_names=["input_ids", "attention_mask"],
                output_names=["embedding"],
                dynamic_axes={
                    "input_ids": {0: "batch", 1: "tokens"},
                    "attention_mask": {0: "batch", 1: "tokens"},
                    "embedding": {0: "batch"},
                },
                opset_version=17,
                dynamo=False,
            )
    except Exception as exc:  # any exporter failure: say what to do instead
        raise RuntimeError(
            f"exporting {model_dir} to ONNX failed ({type(exc).__name__}: {exc}); "
            "use encoder_runtime: torch"
        ) from exc


def _export_error(onnx_file: Path, model_dir: Path, expected: NDArray[np.float32]) -> float:
    """Largest ``|ONNX - PyTorch|`` embedding component on the probe sentences.

    Raises:
        RuntimeError: if it exceeds :data:`EXPORT_TOLERANCE`.
    """
    got = OnnxSentenceRunner(onnx_file, model_dir, threads=1).embed(list(_PROBES))
    worst = float(np.max(np.abs(got - expected)))
    if worst > EXPORT_TOLERANCE:
        raise RuntimeError(
            f"the ONNX export of {model_dir} differs from PyTorch by {worst:.2e} "
            f"(> {EXPORT_TOLERANCE:g}); use encoder_runtime: torch"
        )
    return worst


def load_tokenizer(model_dir: Path) -> Any:
    """The fast tokenizer of ``model_dir``, set up as sentence-transformers calls it: pad to
    the longest sentence of a batch, truncate (longest first) at the model's
    ``max_seq_length``. Uses the ``tokenizers`` library alone, which loads in milliseconds.

    Raises:
        FileNotFoundError: if the tokenizer or sentence-transformers config is missing.
    """
    from tokenizers import Tokenizer

    for name in ("tokenizer.json", "sentence_bert_config.json", "tokenizer_config.json"):
        if not (model_dir / name).is_file():
            raise FileNotFoundError(f"{name} not found in {model_dir}")
    st_config = json.loads((model_dir / "sentence_bert_config.json").read_text())
    pad_token = json.loads((model_dir / "tokenizer_config.json").read_text())["pad_token"]
    if isinstance(pad_token, dict):  # an AddedToken record
        pad_token = pad_token["content"]
    tokenizer = Tokenizer.from_file(str(model_dir / "tokenizer.json"))
    pad_id = tokenizer.token_to_id(pad_token)
    if pad_id is None:
        raise FileNotFoundError(f"padding token {pad_token!r} is not in {model_dir} vocabulary")
    tokenizer.enable_truncation(max_length=int(st_config.get("max_seq_length", 512)))
    tokenizer.enable_padding(pad_id=pad_id, pad_token=pad_token)
    return tokenizer


class OnnxSentenceRunner:
    """Tokenizer plus ONNX Runtime session for one exported encoder (no PyTorch)."""

    def __init__(self, onnx_file: Path, model_dir: Path, threads: int) -> None:
        """Open ``onnx_file`` with the tokenizer of ``model_dir``.

        Args:
            onnx_file: an export made by :func:`export_onnx`.
            model_dir: the sentence-transformers model it was exported from.
            threads: ONNX Runtime intra-op threads.
        """
        import onnxruntime as ort

        options = ort.SessionOptions()
        options.intra_op_num_threads = threads
        options.inter_op_num_threads = 1
        # no busy-waiting between requests: the simulation shares the CPU
        options.add_session_config_entry("session.intra_op.allow_spinning", "0")
        self._session = ort.InferenceSession(
            str(onnx_file), options, providers=["CPUExecutionProvider"]
        )
        self._tokenizer = load_tokenizer(Path(model_dir))
        self.dim = int(self._session.get_outputs()[0].shape[-1])
        self._lock = threading.Lock()

    def tokens(self, texts: list[str]) -> dict[str, NDArray[np.int64]]:
        """Token ids and attention mask as sentence-transformers builds them."""
        with self._lock:  # the tokenizer's padding state is shared
            encodings = self._tokenizer.encode_batch(texts)
        return {
            "input_ids": np.array([e.ids for e in encodings], dtype=np.int64),
            "attention_mask": np.array([e.attention_mask for e in encodings], dtype=np.int64),
        }

    def embed(self, texts: list[str]) -> NDArray[np.float32]:
        """Unit-norm embeddings of ``texts`` (one batch), shape ``(len(texts), dim)``."""
        if not texts:
            return np.zeros((0, self.dim), dtype=np.float32)
        feeds = self.tokens(texts)
        with self._lock:
            (out,) = self._session.run(None, feeds)
        return np.asarray(out, dtype=np.float32)
