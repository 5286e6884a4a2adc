"""LLM-1's fine-tuning of the sentence encoder, stored small: low-rank adapters (LoRA).

Every dense layer of the encoder's six transformer blocks (attention query, key, value and
output, the feed-forward layers) learns a low-rank change ``W' = W + (alpha / rank) B A``
with ``A`` of shape ``(rank, in)`` and ``B`` of shape ``(out, rank)``. Only ``A``, ``B`` and
the classification head are trained and shipped (about 1 MB); the encoder's own weights
stay those of the pinned package and are merged with the change when the model is loaded
(:func:`merge`), so the running encoder is an ordinary one, exported to ONNX like any other.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

TARGETS = re.compile(
    r"encoder\.layer\.\d+\.(attention\.self\.(query|key|value)|attention\.output\.dense|"
    r"intermediate\.dense|output\.dense)$"
)
"""The dense layers that learn a change (names as in the encoder's ``model.safetensors``)."""


@dataclass(frozen=True)
class AdapterSpec:
    """The shape of the low-rank change.

    Attributes:
        rank: the rank of each change.
        alpha: the change is scaled by ``alpha / rank``.
    """

    rank: int = 8
    alpha: float = 16.0

    @property
    def scale(self) -> float:
        """The factor of ``B A``."""
        return self.alpha / self.rank


def merge(
    weights: dict[str, NDArray[np.floating]],
    adapters: dict[str, tuple[NDArray[np.floating], NDArray[np.floating]]],
    spec: AdapterSpec,
) -> dict[str, NDArray[np.float32]]:
    """The encoder's weights with each adapter's change added.

    Args:
        weights: the encoder's tensors by name (``encoder.layer.0.attention.self.query.weight``
            and so on); a name may carry a ``bert.`` prefix, as some exports do.
        adapters: ``(A, B)`` by layer name (``encoder.layer.0.attention.self.query``).
        spec: the adapters' rank and scale.

    Raises:
        ValueError: if an adapter names no weight of the encoder or its shapes do not fit.
    """
    out = {name: np.asarray(w, dtype=np.float32) for name, w in weights.items()}
    for layer, (a, b) in adapters.items():
        name = _weight_name(out, layer)
        w = out[name]
        if a.shape != (spec.rank, w.shape[1]) or b.shape != (w.shape[0], spec.rank):
            raise ValueError(
                f"adapter {layer}: shapes A{a.shape} B{b.shape} do not fit weight {w.shape} "
                f"at rank {spec.rank}"
            )
        out[name] = w + spec.scale * (np.asarray(b, np.float32) @ np.asarray(a, np.float32))
    return out


def _weight_name(weights: dict[str, Any], layer: str) -> str:
    for name in (f"{layer}.weight", f"bert.{layer}.weight"):
        if name in weights:
            return name
    raise ValueError(f"adapter {layer}: the encoder has no weight {layer}.weight")
