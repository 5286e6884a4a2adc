"""Vectorised environments: one SUMO simulation per worker process.

libsumo runs a single simulation per process, so parallel collection needs processes.
Unlike Gymnasium's vector envs there is no automatic reset: the trainer resets a finished
env itself, because every episode gets its own seed, traffic level and command schedule.
:class:`SyncVecEnv` offers the same interface in-process (tests, ``--envs 1``).

Steps and resets are split into a request (``*_async``) and its answer (``*_wait``), so the
caller can learn while the workers simulate. Workers may return only some info keys
(``info_keys``), which keeps the per-step pipe traffic small.
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

    def reset_async(
        self, indices: Sequence[int], seeds: Sequence[int], options: Sequence[dict[str, Any]]
    ) -> None:
        """Ask the envs ``indices`` to start an episode."""
        ...

    def reset_wait(self, indices: Sequence[int]) -> tuple[np.ndarray, list[dict[str, Any]]]:
        """The observations and infos of the resets asked of ``indices``."""
        ...

    def step_async(self, indices: Sequence[int], actions: np.ndarray) -> None:
        """Ask the envs ``indices`` to step."""
        ...

    def step_wait(self, indices: Sequence[int]) -> StepResult:
        """(obs, rewards, terminated, truncated, infos) of the steps asked of ``indices``."""
        ...

    def close(self) -> None:
        """Release the environments."""
        ...


def reset(
    vec: VecEnv,
    indices: Sequence[int],
    seeds: Sequence[int],
    options: Sequence[dict[str, Any]],
) -> tuple[np.ndarray, list[dict[str, Any]]]:
    """Reset and wait."""
    vec.reset_async(indices, seeds, options)
    return vec.reset_wait(indices)


def step(vec: VecEnv, indices: Sequence[int], actions: np.ndarray) -> StepResult:
    """Step and wait."""
    vec.step_async(indices, actions)
    return vec.step_wait(indices)


def _select(info: dict[str, Any], keys: tuple[str, ...] | None) -> dict[str, Any]:
    if keys is None:
        return info
    return {k: info[k] for k in keys if k in info}


class SyncVecEnv:
    """All environments in the calling process (a request runs when its answer is asked)."""

    def __init__(
        self, factories: Sequence[EnvFactory], info_keys: tuple[str, ...] | None = None
    ) -> None:
        self.envs = [f() for f in factories]
        self.num_envs = len(self.envs)
        self.info_keys = info_keys
        self._resets: dict[int, tuple[int, dict[str, Any]]] = {}
        self._actions: dict[int, int] = {}

    def reset_async(
        self, indices: Sequence[int], seeds: Sequence[int], options: Sequence[dict[str, Any]]
    ) -> None:
        """See :meth:`VecEnv.reset_async`."""
        for i, s, o in zip(indices, seeds, options, strict=True):
            self._resets[i] = (int(s), o)

    def reset_wait(self, indices: Sequence[int]) -> tuple[np.ndarray, list[dict[str, Any]]]:
        """See :meth:`VecEnv.reset_wait`."""
        results = [_safe_reset(self.envs[i], *self._resets.pop(i)) for i in indices]
        return np.stack([r[0] for r in results]).astype(np.float32), [r[1] for r in results]

    def step_async(self, indices: Sequence[int], actions: np.ndarray) -> None:
        """See :meth:`VecEnv.step_async`."""
        for i, a in zip(indices, actions, strict=True):
            self._actions[i] = int(a)

    def step_wait(self, indices: Sequence[int]) -> StepResult:
        """See :meth:`VecEnv.step_wait`."""
        results = []
        for i in indices:
            obs, rew, term, trunc, info = self.envs[i].step(self._actions.pop(i))
            results.append((obs, rew, term, trunc, _select(info, self.info_keys)))
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


def _worker(conn: Connection, factory: EnvFactory, info_keys: tuple[str, ...] | None) -> None:
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
                obs, rew, term, trunc, info = env.step(int(data))
                conn.send(("ok", (obs, rew, term, trunc, _select(info, info_keys))))
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
        info_keys: the info keys the workers return (all when ``None``).
        start_method: multiprocessing start method; ``spawn`` keeps the workers free of the
            parent's torch threads and of any simulation state.

    Raises:
        RuntimeError: naming the env, if a worker fails to build its env or to step it.
    """

    def __init__(
        self,
        factories: Sequence[EnvFactory],
        info_keys: tuple[str, ...] | None = None,
        start_method: str = "spawn",
    ) -> None:
        ctx: Any = mp.get_context(start_method)
        self.num_envs = len(factories)
        self._conns: list[Connection] = []
        self._procs: list[mp.process.BaseProcess] = []
        self._closed = False
        for i, factory in enumerate(factories):
            parent, child = ctx.Pipe()
            proc = ctx.Process(
                target=_worker,
                args=(child, factory, info_keys),
                name=f"explaindrive-env-{i}",
                daemon=True,
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

    def reset_async(
        self, indices: Sequence[int], seeds: Sequence[int], options: Sequence[dict[str, Any]]
    ) -> None:
        """See :meth:`VecEnv.reset_async`; the envs reset in parallel."""
        for i, s, o in zip(indices, seeds, options, strict=True):
            self._conns[i].send(("reset", (int(s), o)))

    def reset_wait(self, indices: Sequence[int]) -> tuple[np.ndarray, list[dict[str, Any]]]:
        """See :meth:`VecEnv.reset_wait`."""
        results = [self._recv(i) for i in indices]
        return np.stack([r[0] for r in results]).astype(np.float32), [r[1] for r in results]

    def step_async(self, indices: Sequence[int], actions: np.ndarray) -> None:
        """See :meth:`VecEnv.step_async`; the envs step in parallel."""
        for i, a in zip(indices, actions, strict=True):
            self._conns[i].send(("step", int(a)))

    def step_wait(self, indices: Sequence[int]) -> StepResult:
        """See :meth:`VecEnv.step_wait`."""
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


def make_vec_env(
    factory: EnvFactory,
    num_envs: int,
    subprocess: bool | None = None,
    info_keys: tuple[str, ...] | None = None,
) -> VecEnv:
    """``num_envs`` copies of ``factory``'s env; in subprocesses unless ``num_envs == 1``."""
    if num_envs <= 0:
        raise ValueError(f"num_envs must be > 0, got {num_envs}")
    use_procs = num_envs > 1 if subprocess is None else subprocess
    factories = [factory] * num_envs
    if use_procs:
        return SubprocVecEnv(factories, info_keys)
    return SyncVecEnv(factories, info_keys)
