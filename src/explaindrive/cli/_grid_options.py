"""Options shared by ``explaindrive evaluate``, ``report`` and ``train``: one place each."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Annotated

import typer

FastPolicyOption = Annotated[
    Path | None, typer.Option("--fast-policy", help="Fast policy file instead of the shipped.")
]
ComfortPolicyOption = Annotated[
    Path | None,
    typer.Option("--comfort-policy", help="Comfort policy file instead of the shipped."),
]
ShieldOption = Annotated[
    bool,
    typer.Option("--shield/--no-shield", help="Agents act through the safety shield."),
]
WorkersOption = Annotated[
    int | None, typer.Option("--workers", min=1, help="Processes (default: one per CPU).")
]
RayOption = Annotated[bool, typer.Option("--ray", help="Run the episodes on a local Ray.")]
RayAddressOption = Annotated[
    str | None, typer.Option("--ray-address", help="Run the episodes on this Ray cluster.")
]
TrafficOption = Annotated[str, typer.Option("--traffic", help="Traffic levels, comma-separated.")]
JsonOption = Annotated[
    Path | None, typer.Option("--json", help="Write every episode and the aggregates here.")
]
MaxStepsOption = Annotated[
    int, typer.Option("--max-steps", min=1, help="Step limit per episode [s].")
]


def check_ray_target(ray: bool, ray_address: str | None) -> str | None:
    """The error message when both ``--ray`` and ``--ray-address`` are given, or when either
    is given without Ray installed; else ``None``."""
    if ray and ray_address:
        return "give --ray or --ray-address, not both"
    if (ray or ray_address) and importlib.util.find_spec("ray") is None:
        from explaindrive.agent.ray_pool import RAY_MISSING

        return RAY_MISSING
    return None
