"""Run evaluation episodes: one at a time, on a local process pool, or as Ray tasks.

libsumo runs one simulation per process, so parallel episodes run in separate processes:
a ``spawn`` process pool by default, or Ray tasks (``ray_address`` for a cluster, ``use_ray``
for a local Ray). Each episode builds its env, drives it and closes it, and results come
back in the order of the grid, so the backend does not change the numbers.
"""

from __future__ import annotations

import contextlib
import functools
import logging
import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from explaindrive.commands import Command
from explaindrive.env.actions import IDLE_ACTION
from explaindrive.env.metrics import EpisodeMetrics, EpisodeResult
from explaindrive.evaluation.spec import EpisodeSpec, PolicySpec
from explaindrive.processes import children_ignore_sigint

if TYPE_CHECKING:
    from explaindrive.env.config import EnvConfig
    from explaindrive.env.urban_drive import UrbanDriveEnv

log = logging.getLogger(__name__)

Progress = Callable[[int, int], None]
"""Called with (episodes done, episodes in the grid) after each episode."""


@dataclass(frozen=True, slots=True)
class EpisodeRecord:
    """One evaluated episode: its spec, figures and per-step trace.

    Attributes:
        spec: what was run.
        result: the episode's figures (see :mod:`explaindrive.env.metrics`).
        speeds_mps: ego speed after each step [m/s].
        commands: the command under which each step's action was taken.
        shield_overrides: steps in which the safety shield replaced the policy's action
            (with ``--no-shield``: would have replaced it).
    """

    spec: EpisodeSpec
    result: EpisodeResult
    speeds_mps: tuple[float, ...]
    commands: tuple[str, ...]
    shield_overrides: int = 0


@functools.lru_cache(maxsize=8)
def _load_driver(policy: PolicySpec) -> Any:
    from explaindrive.agent.controller import MergedController, QPolicy

    if policy.kind == "merged":
        fast, comfort = policy.paths
        return MergedController.from_files(fast, comfort, use_shield=policy.shield)
    agent = QPolicy.load(policy.paths[0])
    # One agent under its own command and stop: the merged controller over it twice.
    return MergedController(agent, agent, Command.parse(policy.primary), use_shield=policy.shield)


def _decide(policy: PolicySpec, driver: Any, env: Any, obs: np.ndarray) -> int:
    if policy.kind == "baseline":
        return IDLE_ACTION  # SUMO drives the ego; the action is ignored
    driver.follow(env)  # the env holds the command (and its schedule)
    return int(driver.act(obs))


def run_episode(
    spec: EpisodeSpec, after_reset: Callable[[UrbanDriveEnv], None] | None = None
) -> EpisodeRecord:
    """Drive one episode and measure it; the same spec gives the same record.

    ``after_reset(env)`` runs once the ego has entered, before the first step (for example
    to change the ego's SUMO parameters).

    Args:
        spec: the episode to run.
        after_reset: called with the env once, after the reset.

    Returns:
        The episode's spec, figures, per-step trace and shield overrides.

    Raises:
        CheckpointError: if a policy file cannot be loaded.
        RuntimeError: if the ego cannot enter the road.
    """
    from explaindrive.env.urban_drive import UrbanDriveEnv

    policy = spec.policy
    driver = _start_driver(policy)
    overrides_before = driver.overrides if driver is not None else 0
    config = _env_config(spec, driver)
    env = UrbanDriveEnv(config=config)
    try:
        obs = _reset(env, spec)
        if driver is not None:
            driver.begin(config.obs_noise[1])
        if after_reset is not None:
            after_reset(env)
        trace = _drive(policy, driver, env, obs)
    finally:
        env.close()
    log.debug("episode %s seed=%d level=%g: %d steps", policy.name, spec.seed,
              spec.traffic_level, len(trace.speeds_mps))  # fmt: skip
    overrides = (driver.overrides - overrides_before) if driver is not None else 0
    return EpisodeRecord(
        spec, trace.metrics.result(), tuple(trace.speeds_mps), tuple(trace.commands), overrides
    )


def _start_driver(policy: PolicySpec) -> Any:
    """The policy's (cached) controller, set to drive under its first command.

    Args:
        policy: the policy of the episode.

    Returns:
        The :class:`~explaindrive.agent.controller.MergedController`; ``None`` for a
        baseline (SUMO drives the ego).

    Raises:
        CheckpointError: if a policy file cannot be loaded.
    """
    if policy.kind == "baseline":
        return None
    driver = _load_driver(policy)
    driver.active_agent = Command.FAST if policy.kind == "merged" else Command.parse(policy.primary)
    return driver


def _env_config(spec: EpisodeSpec, driver: Any) -> EnvConfig:
    """The env's config for an episode.

    Baselines see no observation noise; a network drives in the environment it was trained
    in (its yellow-light rule, its speed limiter).

    Args:
        spec: the episode.
        driver: its controller from :func:`_start_driver` (``None`` for a baseline).

    Returns:
        The config to build the env with.
    """
    from explaindrive.env.config import EnvConfig

    policy = spec.policy
    config = EnvConfig(
        traffic_level=spec.traffic_level,
        max_steps=spec.max_steps,
        ego_model=policy.ego_model,
        obs_noise=spec.obs_noise if policy.kind != "baseline" else (0.0, 0.0),
        **dict(spec.scenario),
    )
    if driver is not None:
        config = config.replace(
            yellow_leader=driver.yellow_leader, speed_limiter=driver.speed_limiter
        )
    return config


def _reset(env: UrbanDriveEnv, spec: EpisodeSpec) -> np.ndarray:
    """Reset ``env`` to the episode's seed, traffic level, command and command schedule.

    Args:
        env: the episode's env.
        spec: the episode.

    Returns:
        The first observation.

    Raises:
        RuntimeError: if the ego cannot enter the road.
    """
    obs, _info = env.reset(
        seed=spec.seed,
        options={
            "command": spec.command,
            "traffic_level": spec.traffic_level,
            "command_schedule": [list(item) for item in spec.schedule],
        },
    )
    return obs


@dataclass(slots=True)
class _Trace:
    """What the steps of one episode recorded."""

    metrics: EpisodeMetrics = field(default_factory=EpisodeMetrics)
    speeds_mps: list[float] = field(default_factory=list)
    """Ego speed after each step [m/s]."""
    commands: list[str] = field(default_factory=list)
    """The command under which each step's action was taken."""


def _drive(policy: PolicySpec, driver: Any, env: UrbanDriveEnv, obs: np.ndarray) -> _Trace:
    """Step ``env`` from ``obs`` until the episode terminates or is truncated.

    Args:
        policy: the policy of the episode.
        driver: its controller (``None`` for a baseline).
        env: the env, just reset.
        obs: its first observation.

    Returns:
        The metrics, speeds and commands of every step.
    """
    trace = _Trace()
    done = False
    while not done:
        action = _decide(policy, driver, env, obs)
        obs, reward, terminated, truncated, info = env.step(action)
        trace.metrics.update(info, reward)
        trace.speeds_mps.append(float(info["speed_mps"]))
        trace.commands.append(str(info["command"]))
        done = terminated or truncated
    return trace


def _worker_init() -> None:
    """Worker processes: one torch thread each (the pool provides the parallelism)."""
    import torch

    torch.set_num_threads(1)


def _ray_episode(spec: EpisodeSpec) -> EpisodeRecord:
    _worker_init()
    return run_episode(spec)


def default_workers(n_episodes: int) -> int:
    """Process count for ``n_episodes``: one per CPU, at most one per episode."""
    return max(1, min(os.cpu_count() or 1, n_episodes))


def shield_counts(records: Sequence[EpisodeRecord]) -> tuple[int, int]:
    """(steps in which the shield replaced the network's action, steps) over ``records``."""
    return sum(r.shield_overrides for r in records), sum(r.result.steps for r in records)


def run_grid(
    specs: Sequence[EpisodeSpec],
    *,
    workers: int | None = None,
    use_ray: bool = False,
    ray_address: str | None = None,
    progress: Progress | None = None,
) -> list[EpisodeRecord]:
    """Run every episode of ``specs``; records come back in the order of ``specs``.

    Args:
        specs: the grid.
        workers: processes of the local pool (``1``: run in this process), or CPUs of a
            local Ray; default: one per CPU.
        use_ray: run the episodes as tasks on a local Ray (or the one already initialised).
        ray_address: run them on this Ray cluster (implies ``use_ray``).
        progress: called after each finished episode.

    Raises:
        ValueError: if ``workers`` < 1.
    """
    if workers is not None and (isinstance(workers, bool) or workers < 1):
        raise ValueError(f"workers must be >= 1, got {workers!r}")
    specs = list(specs)
    if not specs:
        return []
    n = workers or default_workers(len(specs))
    if use_ray or ray_address:
        return _run_ray(specs, n, ray_address, progress)
    if n == 1:
        out = []
        for i, spec in enumerate(specs):
            out.append(run_episode(spec))
            if progress:
                progress(i + 1, len(specs))
        return out
    return _run_pool(specs, min(n, len(specs)), progress)


def _run_pool(
    specs: list[EpisodeSpec], workers: int, progress: Progress | None
) -> list[EpisodeRecord]:
    from concurrent.futures import as_completed

    ctx = multiprocessing.get_context("spawn")
    results: list[EpisodeRecord | None] = [None] * len(specs)
    with children_ignore_sigint():  # Ctrl+C stops the run here; the workers are ended
        pool = ProcessPoolExecutor(workers, mp_context=ctx, initializer=_worker_init)
        futures = {pool.submit(run_episode, spec): i for i, spec in enumerate(specs)}
    try:
        for done, future in enumerate(as_completed(futures), start=1):
            results[futures[future]] = future.result()
            if progress:
                progress(done, len(specs))
    except BaseException:  # Ctrl+C, or an episode that failed: stop the others now
        pool.shutdown(wait=False, cancel_futures=True)
        processes = dict(getattr(pool, "_processes", None) or {})  # no public handle
        for process in processes.values():
            with contextlib.suppress(OSError):
                process.terminate()
        raise
    pool.shutdown()
    return [r for r in results if r is not None]


def _run_ray(
    specs: list[EpisodeSpec], workers: int, address: str | None, progress: Progress | None
) -> list[EpisodeRecord]:
    from explaindrive.agent.ray_pool import require_ray, start_ray

    ray = require_ray()
    started = start_ray(address, workers)
    try:
        task = ray.remote(num_cpus=1, max_retries=0)(_ray_episode)
        refs = [task.remote(spec) for spec in specs]
        index = {ref: i for i, ref in enumerate(refs)}
        results: list[EpisodeRecord | None] = [None] * len(specs)
        pending = list(refs)
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            for ref in ready:
                results[index[ref]] = ray.get(ref)
            if progress:
                progress(len(specs) - len(pending), len(specs))
    finally:
        if started:
            ray.shutdown()
    return [r for r in results if r is not None]
