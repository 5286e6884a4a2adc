"""Vectorised environments: one SUMO simulation per worker process.

libsumo runs a single simulation per process, so parallel collection needs processes.
Unlike Gymnasium's vector envs there is no automatic reset: the trainer resets a finished
env itself, because every episode gets its own seed, traffic level and command schedule.
:class:`SyncVecEnv` offers the same interface in-process (tests, ``--envs 1``).
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing as mp
import os
import sys
import traceback
from collections.abc import Callable, Sequence
from multiprocessing.connection import Connection
from typing import Any, Protocol

import gymnasium as gym
import numpy as np

log = logging.getLogger(__name__)

EnvFactory = Callable[[], gym.Env]
"""Builds one environment; must be picklable (a module-level function or a partial)."""

StepResult = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]


class VecEnv(Protocol):
    """What the trainer needs from a vector of environments."""

    num_envs: int

    def reset(
        self, indices: Sequence[int], seeds: Sequence[int], options: Sequence[dict[str, Any]]
    ) -> tuple[np.ndarray, list[dict[str, Any]]]:
        """Reset the envs ``indices``; returns their observations and infos."""
        ...

    def step(self, indices: Sequence[int], actions: np.ndarray) -> StepResult:
        """Step the envs ``indices``; returns (obs, rewards, terminated, truncated, infos)."""
        ...

    def close(self) -> None:
        """Release the environments."""
        ...


class SyncVecEnv:
    """All environments in the calling process."""

    def __init__(self, factories: Sequence[EnvFactory]) -> None:
        self.envs = [f() for f in factories]
        self.num_envs = len(self.envs)

    def reset(
        self, indices: Sequence[int], seeds: Sequence[int], options: Sequence[dict[str, Any]]
    ) -> tuple[np.ndarray, list[dict[str, Any]]]:
        """See :meth:`VecEnv.reset`."""
        results = [
            _safe_reset(self.envs[i], int(s), o)
            for i, s, o in zip(indices, seeds, options, strict=True)
        ]
        return np.stack([r[0] for r in results]).astype(np.float32), [r[1] for r in results]

    def step(self, indices: Sequence[int], actions: np.ndarray) -> StepResult:
        """See :meth:`VecEnv.step`."""
        results = [self.envs[i].step(int(a)) for i, a in zip(indices, actions, strict=True)]
        return _stack(results)

    def close(self) -> None:
        """Close every env."""
        for env in self.envs:
            env.close()


def _stack(results: Sequence[tuple[Any, ...]]) -> StepResult:
    obs, rew, term, trunc, infos = zip(*results, strict=True)
    return (
        np.stack(obs).astype(np.float32),
        np.asarray(rew, dtype=np.float32),
        np.asarray(term, dtype=np.bool_),
        np.asarray(trunc, dtype=np.bool_),
        list(infos),
    )


RESET_FAILED = "reset_failed"
"""Info key set (with the error message) when an env could not start an episode; the
observation is then NaN and the caller should retry with another seed."""


def _safe_reset(env: gym.Env, seed: int, options: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    """``env.reset``, turning a failure to start this episode into a ``RESET_FAILED`` info."""
    try:
        return env.reset(seed=seed, options=options)
    except (RuntimeError, OSError) as exc:  # e.g. the ego cannot enter a blocked road
        log.warning("reset with seed %s failed: %s", seed, exc)
        shape = env.observation_space.shape or (1,)
        return np.full(shape, np.nan, dtype=np.float32), {RESET_FAILED: str(exc)}


def _worker(conn: Connection, factory: EnvFactory) -> None:
    """Worker loop: build the env, then serve ``reset``/``step``/``close`` requests."""
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    if "torch" in sys.modules:  # keep any torch use in the env to one thread
        sys.modules["torch"].set_num_threads(1)
    env = None
    try:
        env = factory()
        conn.send(("ok", None))
        while True:
            cmd, data = conn.recv()
            if cmd == "step":
                conn.send(("ok", env.step(int(data))))
            elif cmd == "reset":
                seed, options = data
                conn.send(("ok", _safe_reset(env, seed, options)))
            elif cmd == "close":
                break
            else:
                conn.send(("error", f"unknown request {cmd!r}"))
    except (EOFError, KeyboardInterrupt):
        pass
    except Exception:
        with contextlib.suppress(BrokenPipeError, OSError):
            conn.send(("error", traceback.format_exc()))
    finally:
        if env is not None:
            env.close()
        conn.close()


class SubprocVecEnv:
    """One environment per worker process, stepped in parallel through pipes.

    Args:
        factories: one picklable env factory per worker.
        start_method: multiprocessing start method; ``spawn`` keeps the workers free of the
            parent's torch threads and of any simulation state.

    Raises:
        RuntimeError: naming the env, if a worker fails to build its env or to step it.
    """

    def __init__(self, factories: Sequence[EnvFactory], start_method: str = "spawn") -> None:
        ctx: Any = mp.get_context(start_method)
        self.num_envs = len(factories)
        self._conns: list[Connection] = []
        self._procs: list[mp.process.BaseProcess] = []
        self._closed = False
        for i, factory in enumerate(factories):
            parent, child = ctx.Pipe()
            proc = ctx.Process(
                target=_worker, args=(child, factory), name=f"explaindrive-env-{i}", daemon=True
            )
            proc.start()
            child.close()
            self._conns.append(parent)
            self._procs.append(proc)
        try:
            for i in range(self.num_envs):
                self._recv(i)
        except BaseException:
            self.close()
            raise

    def _recv(self, i: int) -> Any:
        try:
            status, payload = self._conns[i].recv()
        except EOFError:
            code = self._procs[i].exitcode
            raise RuntimeError(f"env worker {i} died (exit code {code})") from None
        if status == "error":
            raise RuntimeError(f"env worker {i} failed:\n{payload}")
        return payload

    def reset(
        self, indices: Sequence[int], seeds: Sequence[int], options: Sequence[dict[str, Any]]
    ) -> tuple[np.ndarray, list[dict[str, Any]]]:
        """See :meth:`VecEnv.reset`; the envs reset in parallel."""
        for i, s, o in zip(indices, seeds, options, strict=True):
            self._conns[i].send(("reset", (int(s), o)))
        results = [self._recv(i) for i in indices]
        return np.stack([r[0] for r in results]).astype(np.float32), [r[1] for r in results]

    def step(self, indices: Sequence[int], actions: np.ndarray) -> StepResult:
        """See :meth:`VecEnv.step`; the envs step in parallel."""
        for i, a in zip(indices, actions, strict=True):
            self._conns[i].send(("step", int(a)))
        return _stack([self._recv(i) for i in indices])

    def close(self) -> None:
        """Ask every worker to stop, then join (terminating any that hang)."""
        if self._closed:
            return
        self._closed = True
        for conn in self._conns:
            with contextlib.suppress(BrokenPipeError, OSError):
                conn.send(("close", None))
        for proc in self._procs:
            proc.join(timeout=10)
            if proc.is_alive():
                log.warning("env worker %s did not stop; terminating it", proc.name)
                proc.terminate()
                proc.join(timeout=5)
        for conn in self._conns:
            conn.close()


def make_vec_env(factory: EnvFactory, num_envs: int, subprocess: bool | None = None) -> VecEnv:
    """``num_envs`` copies of ``factory``'s env; in subprocesses unless ``num_envs == 1``."""
    if num_envs <= 0:
        raise ValueError(f"num_envs must be > 0, got {num_envs}")
    use_procs = num_envs > 1 if subprocess is None else subprocess
    factories = [factory] * num_envs
    return SubprocVecEnv(factories) if use_procs else SyncVecEnv(factories)
