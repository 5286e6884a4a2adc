"""LLM-1's learned model: a fine-tuned sentence encoder with a reading head that may abstain.

all-MiniLM-L6-v2, fine-tuned end to end through low-rank adapters
(:mod:`~explaindrive.language.intent.adapter`), embeds a line; a linear head gives the
probability of each of seven readings (:data:`READINGS`): the three commands, ``none`` (not
about the driving), ``why`` (a question about what the car is doing), and ``yes`` / ``no``
(an answer to a confirmation question).

The model is open-set by its decision rule (:meth:`IntentModel.decide`): a command is given
only when its probability reaches a threshold chosen on a calibration pool of everyday
language and development requests; below it the line is left without a command. STOP has a
threshold of its own, and below it a band where the car asks back: a line the model reads as
STOP most likely, but not surely, is given no command; the car asks whether to stop, and the
passenger's yes stops it.
"""

from __future__ import annotations

import hashlib
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from explaindrive.cache import cache_dir, is_complete, publish
from explaindrive.commands import COMMAND_LABELS
from explaindrive.language.data import INTENT_MODEL, data_path
from explaindrive.language.intent.adapter import AdapterSpec, merge
from explaindrive.language.packaged import weights_sha256

READINGS: tuple[str, ...] = (*COMMAND_LABELS, "none", "why", "yes", "no")
"""What a line can mean; the first three are the commands (:mod:`explaindrive.commands`)."""
STOP = READINGS.index("stop")
ANSWERS: tuple[str, ...] = ("yes", "no")
"""The readings that answer a confirmation question."""


def answer_of(reading: str | None) -> bool | None:
    """The answer a reading gives to a confirmation question: ``True`` for ``yes``,
    ``False`` for ``no``, ``None`` for any other reading (a new request, say)."""
    return {"yes": True, "no": False}.get(reading or "")


WHY_READING = "why"
"""The reading of a question about what the car is doing."""
N_COMMANDS = len(COMMAND_LABELS)
ENCODER_WEIGHTS = "model.safetensors"


@dataclass(frozen=True)
class Thresholds:
    """The decision rule's thresholds, chosen on the calibration pool.

    Attributes:
        command: a fast or comfort reading needs at least this probability.
        stop: a STOP reading needs at least this probability.
        ask_stop: a line whose most probable reading is STOP, at least this probable but
            short of ``stop``, is asked about (:attr:`Reading.ask_stop`); ``None``: never.
    """

    command: float
    stop: float
    ask_stop: float | None = None


@dataclass(frozen=True)
class Reading:
    """What the model makes of one line.

    Attributes:
        reading: one of :data:`READINGS`; ``none`` also when a command fell short of its
            threshold (``abstained``).
        p: the probability of each reading, in :data:`READINGS` order.
        abstained: the most probable reading was a command below its threshold.
        ask_stop: the most probable reading was STOP, short of its threshold but within the
            band where the car asks whether to stop (:attr:`Thresholds.ask_stop`).
    """

    reading: str
    p: NDArray[np.float64]
    abstained: bool = False
    ask_stop: bool = False

    @property
    def command(self) -> str | None:
        """The command label, or ``None`` when the line asks for none."""
        return self.reading if self.reading in COMMAND_LABELS else None

    def scores(self) -> dict[str, float]:
        """The probabilities by reading, rounded for logs and JSON."""
        return {r: round(float(v), 4) for r, v in zip(READINGS, self.p, strict=True)}


@dataclass(frozen=True)
class IntentModel:
    """The adapters, the head and the thresholds of LLM-1.

    Attributes:
        adapters: ``(A, B)`` of each adapted encoder layer, by layer name.
        spec: the adapters' rank and scale.
        head_w: the reading head's weights, shape ``(len(READINGS), dim)``.
        head_b: its biases.
        thresholds: the decision rule's thresholds.
        base_sha256: the SHA-256 of the encoder weights the adapters were trained on.
    """

    adapters: dict[str, tuple[NDArray[np.float32], NDArray[np.float32]]]
    spec: AdapterSpec
    head_w: NDArray[np.float32]
    head_b: NDArray[np.float32]
    thresholds: Thresholds
    base_sha256: str

    def proba(self, embeddings: NDArray[np.floating]) -> NDArray[np.float64]:
        """The readings' probabilities for unit-norm ``embeddings`` (one row per line)."""
        z = np.asarray(embeddings, dtype=np.float64) @ self.head_w.T.astype(np.float64)
        z = z + self.head_b
        z -= z.max(axis=1, keepdims=True)
        e = np.exp(z)
        return np.asarray(e / e.sum(axis=1, keepdims=True), dtype=np.float64)

    def decide(self, p: NDArray[np.float64], thresholds: Thresholds | None = None) -> Reading:
        """The reading of one probability row.

        STOP when its probability reaches the STOP threshold; else the most probable
        reading, but a command below the command threshold leaves the line without one (a
        STOP within the ask band is asked about).
        """
        t = thresholds or self.thresholds
        p = np.asarray(p, dtype=np.float64)
        if p[STOP] >= t.stop:
            return Reading("stop", p)
        best = int(np.argmax(p))
        if best == STOP:
            ask = t.ask_stop is not None and bool(p[STOP] >= t.ask_stop)
            return Reading("none", p, abstained=True, ask_stop=ask)
        if best < N_COMMANDS and p[best] < t.command:
            return Reading("none", p, abstained=True)
        return Reading(READINGS[best], p)

    def save(self, path: str | Path) -> None:
        """Write the model as ``.npz`` (adapters in float16)."""
        arrays: dict[str, Any] = {}
        for i, (_, (a, b)) in enumerate(sorted(self.adapters.items())):
            arrays[f"a{i}"] = a.astype(np.float16)
            arrays[f"b{i}"] = b.astype(np.float16)
        if self.thresholds.ask_stop is not None:
            arrays["stop_ask_threshold"] = self.thresholds.ask_stop
        np.savez_compressed(
            path,
            layers=np.array(sorted(self.adapters)),
            readings=np.array(READINGS),
            rank=self.spec.rank,
            alpha=self.spec.alpha,
            head_w=self.head_w.astype(np.float32),
            head_b=self.head_b.astype(np.float32),
            command_threshold=self.thresholds.command,
            stop_threshold=self.thresholds.stop,
            base_sha256=self.base_sha256,
            **arrays,
        )

    @classmethod
    def load(cls, path: str | Path | None = None) -> IntentModel:
        """Read a model (default: the shipped one).

        Raises:
            FileNotFoundError: if the file is missing.
            ValueError: if it is not a model written by :meth:`save` or reads other
                readings than :data:`READINGS`.
        """
        p = Path(path) if path is not None else data_path(INTENT_MODEL)
        if not p.is_file():
            raise FileNotFoundError(f"intent model not found: {p}")
        try:
            with np.load(p, allow_pickle=False) as z:
                readings = tuple(str(r) for r in z["readings"])
                layers = [str(x) for x in z["layers"]]
                model = cls(
                    adapters={
                        name: (
                            np.asarray(z[f"a{i}"], np.float32),
                            np.asarray(z[f"b{i}"], np.float32),
                        )
                        for i, name in enumerate(layers)
                    },
                    spec=AdapterSpec(int(z["rank"]), float(z["alpha"])),
                    head_w=np.asarray(z["head_w"], np.float32),
                    head_b=np.asarray(z["head_b"], np.float32),
                    thresholds=Thresholds(
                        float(z["command_threshold"]),
                        float(z["stop_threshold"]),
                        float(z["stop_ask_threshold"]) if "stop_ask_threshold" in z else None,
                    ),
                    base_sha256=str(z["base_sha256"]),
                )
        except (OSError, KeyError, ValueError) as exc:
            raise ValueError(f"{p}: not a valid intent model file ({exc})") from exc
        if readings != READINGS:
            raise ValueError(f"{p}: readings {readings} differ from {READINGS}")
        if model.head_w.shape[0] != len(READINGS) or model.head_b.shape != (len(READINGS),):
            raise ValueError(f"{p}: the head does not have {len(READINGS)} outputs")
        return model

    def digest(self) -> str:
        """A short digest of the adapters, naming the merged encoder in the cache."""
        h = hashlib.sha256(self.base_sha256.encode())
        h.update(f"{self.spec.rank}|{self.spec.alpha}".encode())
        for name in sorted(self.adapters):
            a, b = self.adapters[name]
            h.update(name.encode())
            h.update(np.ascontiguousarray(a, np.float32).tobytes())
            h.update(np.ascontiguousarray(b, np.float32).tobytes())
        return h.hexdigest()[:12]

    def encoder_dir(self, base_dir: Path, root: Path | None = None) -> Path:
        """The fine-tuned encoder as a sentence-transformers folder in the cache, made on
        first use from the encoder in ``base_dir`` and the adapters.

        Raises:
            ValueError: if ``base_dir``'s weights are not the ones the adapters were
                trained on, or an adapter does not fit them.
        """
        target = (root or cache_dir()) / "intent" / f"minilm-ft-{self.digest()}"
        if is_complete(target):
            return target
        from safetensors.numpy import load_file, save_file

        weights_file = base_dir / ENCODER_WEIGHTS
        digest = weights_sha256(weights_file)
        if digest != self.base_sha256:
            raise ValueError(
                f"the intent model was trained on encoder weights {self.base_sha256[:12]}..., "
                f"not {weights_file} ({digest[:12]}...)"
            )
        merged = merge(load_file(str(weights_file)), self.adapters, self.spec)
        target.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=target.parent, prefix=f".{target.name}-") as tmp:
            staged = Path(tmp) / target.name
            shutil.copytree(base_dir, staged, ignore=shutil.ignore_patterns(ENCODER_WEIGHTS))
            save_file(merged, str(staged / ENCODER_WEIGHTS))
            return publish(staged, target, f"adapters {self.digest()} on {digest[:12]}\n")
