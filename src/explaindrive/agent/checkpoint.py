"""Atomic checkpoints of a training run, and the policy files that ship with the package.

A run directory holds ``checkpoints/``:

- ``checkpoint.pt``: networks, optimiser, trainer counters and RNG states, the config, and
  the name of the replay file it belongs to;
- ``replay_<env steps>.npz``: the filled part of the replay buffer at that checkpoint;
- ``config.json``: the resolved config and the counters, readable without torch.

Every file is written to a temporary file in the same directory and moved into place with
:func:`os.replace`, and the replay file is written *before* the checkpoint that names it, so
a run killed at any instant leaves the previous complete checkpoint or the new one.

A policy is ``<name>.pt`` (network weights and shape) plus a ``<name>.json`` card.
"""

from __future__ import annotations

import io
import json
import logging
import os
import tempfile
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any, NamedTuple

import numpy as np
import torch

from explaindrive.agent.config import ConfigError, TrainConfig
from explaindrive.agent.network import DuelingQNetwork

log = logging.getLogger(__name__)

CHECKPOINT_FORMAT = "explaindrive-checkpoint"
POLICY_FORMAT = "explaindrive-policy"
FORMAT_VERSION = 1
CHECKPOINT_FILE = "checkpoint.pt"
CONFIG_FILE = "config.json"
POLICY_FILE = "policy.pt"  # a training run's final policy, its card next to it
# Fields a resumed run must share with its checkpoint; the others (episodes, logging...)
# may change between runs.
STRUCTURAL_FIELDS: tuple[str, ...] = ("mode", "hidden_sizes", "near_range_m", "buffer_size")


class CheckpointError(RuntimeError):
    """A checkpoint or policy file is missing, corrupt or does not match the run."""


def atomic_write(path: Path, write: Callable[[IO[bytes]], object]) -> None:
    """Write a file through ``write(fileobj)`` into a temp file, then ``os.replace`` it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    """:func:`atomic_write` for UTF-8 text."""
    atomic_write(path, lambda f: f.write(text.encode("utf-8")))


class Checkpoint(NamedTuple):
    """What :func:`load_checkpoint` returns."""

    path: Path
    config: dict[str, Any]
    learner: dict[str, Any]
    trainer: dict[str, Any]
    replay: dict[str, np.ndarray] | None


def save_checkpoint(
    directory: Path,
    *,
    config: TrainConfig,
    learner_state: dict[str, Any],
    trainer_state: dict[str, Any],
    replay_state: dict[str, np.ndarray] | None,
) -> Path:
    """Write a complete checkpoint into ``directory`` atomically; returns the ``.pt`` path."""
    directory.mkdir(parents=True, exist_ok=True)
    replay_name = None
    if replay_state is not None:
        replay_name = f"replay_{int(trainer_state['env_steps']):012d}.npz"
        atomic_write(directory / replay_name, lambda f: np.savez(f, **replay_state))  # type: ignore[arg-type]
    payload = {
        "format": CHECKPOINT_FORMAT,
        "version": FORMAT_VERSION,
        "config": config.to_dict(),
        "learner": learner_state,
        "trainer": trainer_state,
        "replay_file": replay_name,
    }
    path = directory / CHECKPOINT_FILE
    atomic_write(path, lambda f: torch.save(payload, f))
    summary = {k: v for k, v in trainer_state.items() if isinstance(v, int | float | str)}
    atomic_write_text(
        directory / CONFIG_FILE,
        json.dumps({"config": config.to_dict(), "trainer": summary}, indent=2, sort_keys=True),
    )
    for stale in directory.glob("replay_*.npz"):
        if stale.name != replay_name:
            stale.unlink(missing_ok=True)
    return path


def _torch_load(path: Path, what: str) -> dict[str, Any]:
    if not path.is_file():
        raise CheckpointError(f"{what} file not found: {path}")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # torch raises many types (with long advice) for a damaged file
        raise CheckpointError(
            f"{path} is not an explaindrive {what} file (torch cannot read it: "
            f"{type(exc).__name__})"
        ) from exc
    if not isinstance(payload, dict):
        raise CheckpointError(f"{path} is not an explaindrive {what} file")
    return payload


def load_checkpoint(directory: Path, config: TrainConfig | None = None) -> Checkpoint:
    """Read the checkpoint of ``directory`` (and its replay file, if it has one).

    Args:
        directory: the ``checkpoints/`` directory of a run.
        config: if given, the checkpoint's :data:`STRUCTURAL_FIELDS` must match it.

    Raises:
        CheckpointError: naming the file, if it is missing, corrupt or mismatched.
    """
    path = directory / CHECKPOINT_FILE
    payload = _torch_load(path, "checkpoint")
    if payload.get("format") != CHECKPOINT_FORMAT:
        raise CheckpointError(f"{path} is not an explaindrive checkpoint")
    if payload.get("version") != FORMAT_VERSION:
        raise CheckpointError(
            f"{path} has format version {payload.get('version')}, expected {FORMAT_VERSION}"
        )
    saved = payload["config"]
    if config is not None:
        try:
            saved_cfg = TrainConfig.from_dict(saved)
        except ConfigError as exc:
            raise CheckpointError(f"{path} holds an invalid config: {exc}") from exc
        diffs = [
            f"{name}: checkpoint {getattr(saved_cfg, name)!r} vs run {getattr(config, name)!r}"
            for name in STRUCTURAL_FIELDS
            if getattr(saved_cfg, name) != getattr(config, name)
        ]
        if diffs:
            raise CheckpointError(f"checkpoint {path} does not match this run: " + "; ".join(diffs))
    replay = None
    if payload.get("replay_file"):
        replay_path = directory / payload["replay_file"]
        if not replay_path.is_file():
            raise CheckpointError(f"replay file not found: {replay_path} (named by {path})")
        try:
            with np.load(replay_path) as data:
                replay = {k: data[k] for k in data.files}
        except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
            raise CheckpointError(f"replay file {replay_path} is corrupt: {exc}") from exc
    return Checkpoint(path, saved, payload["learner"], payload["trainer"], replay)


def save_policy(path: Path, network: DuelingQNetwork, card: dict[str, Any]) -> tuple[Path, Path]:
    """Write ``<path>.pt`` (weights) and the JSON card next to it; returns both paths."""
    path = Path(path).with_suffix(".pt")
    payload = {
        "format": POLICY_FORMAT,
        "version": FORMAT_VERSION,
        "hidden_sizes": list(network.hidden_sizes),
        "state_dim": network.state_dim,
        "n_actions": network.n_actions,
        "near_range_m": network.near_range_m,
        "state_dict": network.state_dict(),
    }
    buf = io.BytesIO()
    torch.save(payload, buf)
    atomic_write(path, lambda f: f.write(buf.getvalue()))
    card_path = path.with_suffix(".json")
    atomic_write_text(card_path, json.dumps(card, indent=2, sort_keys=True, default=str))
    return path, card_path


def policy_file(path: str | Path) -> Path:
    """The policy file ``path`` names: a training run directory's :data:`POLICY_FILE`, else
    ``path`` with the ``.pt`` suffix (which :func:`load_policy` reads). Not checked to exist."""
    p = Path(path).expanduser()
    return p / POLICY_FILE if p.is_dir() else p.with_suffix(".pt")


def load_policy(path: Path) -> tuple[DuelingQNetwork, dict[str, Any]]:
    """Load a policy network (in eval mode) and its card.

    Raises:
        CheckpointError: naming the file, if either is missing, corrupt or malformed.
    """
    path = Path(path).with_suffix(".pt")
    payload = _torch_load(path, "policy")
    if payload.get("format") != POLICY_FORMAT:
        raise CheckpointError(f"{path} is not an explaindrive policy file")
    try:
        net = DuelingQNetwork(
            payload["hidden_sizes"],
            payload["state_dim"],
            payload["n_actions"],
            payload.get("near_range_m"),  # absent from files saved before the option
        )
        net.load_state_dict(payload["state_dict"])
    except (KeyError, RuntimeError, ValueError) as exc:
        raise CheckpointError(f"policy file {path} does not hold a valid network: {exc}") from exc
    card_path = path.with_suffix(".json")
    try:
        card = json.loads(card_path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CheckpointError(f"policy card not found: {card_path}") from None
    except (OSError, json.JSONDecodeError) as exc:
        raise CheckpointError(f"policy card {card_path} is unreadable: {exc}") from exc
    net.eval()
    return net, card
