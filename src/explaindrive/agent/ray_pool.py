"""Rollout workers as Ray actors: ``explaindrive train --ray [--ray-address ADDR]``.

Each actor holds one :class:`~explaindrive.agent.rollout.RolloutWorker` (one SUMO
simulation, as libsumo requires); the learner stays on the driver. The weights of a round go
into the object store once and every actor reads them from there. An actor that dies is
restarted by Ray (``max_restarts=-1``); the round it was playing comes back as
:class:`~explaindrive.agent.pool.WorkerLost`. Ray is the optional extra
``explaindrive[ray]``.
"""

from __future__ import annotations

import importlib.util
import logging
import os
import socket
import threading
import time
from collections.abc import Sequence
from dataclasses import replace
from types import ModuleType
from typing import Any

from explaindrive.agent.config import ConfigError, TrainConfig
from explaindrive.agent.pool import RoundResult, WorkerLost
from explaindrive.agent.rollout import CollectRequest, EnvFactory, Rollout, RolloutWorker
from explaindrive.limits import RAY_CONNECT_TIMEOUT_S

log = logging.getLogger(__name__)

RAY_MISSING = "Ray is not installed: pip install 'explaindrive[ray]'"


def ray_installed() -> bool:
    """Whether Ray (the optional extra) is installed; the one place that checks, without
    importing it."""
    return importlib.util.find_spec("ray") is not None


def require_ray() -> ModuleType:
    """The ``ray`` module.

    Raises:
        ConfigError: naming the extra, if Ray is not installed.
    """
    if not ray_installed():
        raise ConfigError(RAY_MISSING)
    import ray

    return ray


def unreachable_ray_address(address: str, timeout_s: float = RAY_CONNECT_TIMEOUT_S) -> str | None:
    """Why nothing answers at the Ray cluster ``address`` (``host:port`` or
    ``ray://host:port``) within ``timeout_s``, or ``None`` if a TCP connection opens
    (``auto`` and ``local`` are left to Ray). Ray itself retries an address that does not
    answer for minutes; this check makes such a run fail at once.
    """
    if address in ("auto", "local"):
        return None
    host, sep, port = address.removeprefix("ray://").rpartition(":")
    host = host.strip("[]")  # an IPv6 address in brackets
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        return f"--ray-address {address!r} is not host:port (e.g. 10.0.0.5:6379)"
    outcome: list[str | None] = []

    def connect() -> None:  # the name lookup has no timeout of its own: a thread bounds it
        try:
            with socket.create_connection((host, int(port)), timeout=timeout_s):
                outcome.append(None)
        except OSError as exc:
            outcome.append(exc.strerror or type(exc).__name__)

    worker = threading.Thread(target=connect, daemon=True, name="ray-address-check")
    worker.start()
    worker.join(timeout_s)
    reason = outcome[0] if outcome else f"no answer within {timeout_s:g} s"
    if reason is None:
        return None
    return f"no Ray cluster answers at --ray-address {address} ({reason})"


class RayRolloutActor:
    """The body of a Ray actor: a rollout worker that also reports its process id."""

    def __init__(self, config: TrainConfig, env_factory: EnvFactory, worker_id: int) -> None:
        self.worker = RolloutWorker(config, env_factory, worker_id)

    def collect(self, request: CollectRequest, weights: Any = None) -> Rollout:
        """Play one round; ``weights`` (resolved from the object store) replace the request's."""
        if weights is not None:
            request = replace(request, weights=weights)
        return self.worker.collect(request)

    def pid(self) -> int:
        """The actor's process id."""
        return os.getpid()


def start_ray(address: str | None, num_cpus: int) -> bool:
    """Connect to the cluster at ``address``, or start a local Ray of ``num_cpus`` CPUs,
    unless Ray is running in this process already; returns whether it was started here
    (the caller then shuts it down).

    Raises:
        ConfigError: naming the extra, if Ray is not installed.
    """
    ray = require_ray()
    if ray.is_initialized():
        return False
    if address:
        ray.init(address=address, include_dashboard=False, log_to_driver=False)
    else:
        ray.init(num_cpus=num_cpus, include_dashboard=False, log_to_driver=False)
    return True


class RayPool:
    """``num_workers`` rollout actors on a local Ray or on the cluster at ``address``."""

    def __init__(
        self,
        config: TrainConfig,
        env_factory: EnvFactory,
        num_workers: int,
        address: str | None = None,
    ) -> None:
        self.ray = ray = require_ray()
        self.num_workers = num_workers
        self._owns_ray = start_ray(address, max(num_workers, os.cpu_count() or 1))
        actor = ray.remote(num_cpus=1, max_restarts=-1, max_task_retries=0)(RayRolloutActor)
        self.actors = [actor.remote(config, env_factory, i) for i in range(num_workers)]
        self._refs: list[Any] = []

    def submit(self, requests: Sequence[CollectRequest]) -> None:
        """See :meth:`~explaindrive.agent.workers.WorkerPool.submit`."""
        weights = next((r.weights for r in requests if r.weights is not None), None)
        shared = self.ray.put(weights) if weights is not None else None
        self._refs = [
            actor.collect.remote(
                replace(r, weights=None), shared if r.weights is not None else None
            )
            for actor, r in zip(self.actors, requests, strict=True)
        ]

    def gather(self) -> list[RoundResult]:
        """See :meth:`~explaindrive.agent.workers.WorkerPool.gather`."""
        out: list[RoundResult] = []
        for i, ref in enumerate(self._refs):
            try:
                out.append(self.ray.get(ref))
            except self.ray.exceptions.RayActorError as exc:
                out.append(WorkerLost(i, type(exc).__name__))
                self._await_restart(i)
        return out

    def _await_restart(self, i: int, timeout_s: float = 120.0) -> None:
        """Wait until Ray has restarted actor ``i`` (its next round would fail before)."""
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                self.ray.get(self.actors[i].pid.remote(), timeout=timeout_s)
                return
            except self.ray.exceptions.RayActorError:
                if time.monotonic() > deadline:
                    msg = f"Ray did not restart worker {i} within {timeout_s:.0f} s"
                    raise RuntimeError(msg) from None
                time.sleep(0.5)

    def pids(self) -> list[int]:
        """Process ids of the actors (tests kill one)."""
        return [int(pid) for pid in self.ray.get([a.pid.remote() for a in self.actors])]

    def close(self) -> None:
        """Stop the actors, and Ray if this pool started it."""
        for actor in self.actors:
            self.ray.kill(actor)
        if self._owns_ray:
            self.ray.shutdown()
