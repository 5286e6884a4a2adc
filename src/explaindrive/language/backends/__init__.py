"""Backend registry: ``embedded`` (offline, default) and ``openai`` (any compatible endpoint)."""

from __future__ import annotations

BACKENDS: tuple[str, ...] = ("embedded", "openai")


def check_backend(name: str) -> str:
    """Return ``name`` if it is a known backend.

    Raises:
        ValueError: naming the known backends otherwise.
    """
    if name not in BACKENDS:
        raise ValueError(f"unknown language backend {name!r}; choose one of: {', '.join(BACKENDS)}")
    return name
