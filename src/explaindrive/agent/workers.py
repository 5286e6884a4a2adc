"""Pools of rollout workers: in this process, in local processes, or as Ray actors.

A pool takes one :class:`~explaindrive.agent.rollout.CollectRequest` per worker
(:meth:`WorkerPool.submit`), lets the workers play while the caller learns, and returns
their :class:`~explaindrive.agent.rollout.Rollout` in worker order (:meth:`WorkerPool.gather`).
A Ray actor that dies is restarted by Ray; its round comes back as :class:`WorkerLost` and
the caller replays the episode it was playing. Local worker processes that die stop the run
with an error naming the worker. The types every pool shares are in
:mod:`explaindrive.agent.pool`.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import multiprocessing as mp
import os
import signal
import sys
import traceback
from collections.abc import Sequence
from multiprocessing.connection import Connection
from typing import Any

from explaindrive.agent.config import TrainConfig
from explaindrive.agent.pool import RoundResult, WorkerPool
from explaindrive.agent.rollout import CollectRequest, EnvFactory, RolloutWorker
from explaindrive.processes import children_ignore_sigint, restore_sigint

log = logging.getLogger(__name__)


class InProcessPool:
    """Workers in the calling process; a round runs when it is gathered (tests, one env)."""

    def __init__(self, config: TrainConfig, env_factory: EnvFactory, num_workers: int) -> None:
        self.workers = [RolloutWorker(config, env_factory, i) for i in range(num_workers)]
        self.num_workers = num_workers
        self._requests: Sequence[CollectRequest] = ()

    def submit(self, requests: Sequence[CollectRequest]) -> None:
        """See :meth:`WorkerPool.submit`."""
        self._requests = requests

    def gather(self) -> list[RoundResult]:
        """See :meth:`WorkerPool.gather`."""
        return [w.collect(r) for w, r in zip(self.workers, self._requests, strict=True)]

    def close(self) -> None:
        """See :meth:`WorkerPool.close`."""
        for worker in self.workers:
            worker.close()


_PR_SET_PDEATHSIG = 1  # prctl option: the signal this process gets when its parent dies


def _end_with_parent(parent_pid: int) -> None:
    """On Linux, have the kernel end this process when ``parent_pid`` dies (a killed trainer
    must not leave workers playing their round); elsewhere the next pipe read ends it."""
    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != parent_pid:  # the parent died before the signal was armed
        os._exit(1)


def _serve(
    conn: Connection, config: TrainConfig, factory: EnvFactory, worker_id: int, parent_pid: int
) -> None:
    """Process loop: build the worker, then answer ``collect`` until ``close``."""
    _end_with_parent(parent_pid)
    restore_sigint()  # ignored while this process imported its modules
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    worker = None
    try:
        worker = RolloutWorker(config, factory, worker_id)
        conn.send(("ok", None))
        while True:
            cmd, data = conn.recv()
            if cmd == "close":
                break
            conn.send(("ok", worker.collect(data)))
    except (EOFError, KeyboardInterrupt):
        pass
    except Exception:
        with contextlib.suppress(BrokenPipeError, OSError):
            conn.send(("error", traceback.format_exc()))
    finally:
        if worker is not None:
            worker.close()
        conn.close()


class ProcessPool:
    """One worker per local process (``spawn``: no inherited torch threads or SUMO state).

    On Linux a worker ends when the thread that built the pool ends, so build it in a
    thread that outlives it (the trainer builds it in the caller's thread); a trainer
    killed by any signal leaves no worker behind.

    Raises:
        RuntimeError: naming the worker, if one fails to start or to play its round.
    """

    def __init__(self, config: TrainConfig, env_factory: EnvFactory, num_workers: int) -> None:
        ctx: Any = mp.get_context("spawn")
        self.num_workers = num_workers
        self._conns: list[Connection] = []
        self._procs: list[mp.process.BaseProcess] = []
        self._closed = False
        for i in range(num_workers):
            parent, child = ctx.Pipe()
            proc = ctx.Process(target=_serve, args=(child, config, env_factory, i, os.getpid()),
                               name=f"explaindrive-worker-{i}", daemon=True)  # fmt: skip
            with children_ignore_sigint():  # no traceback from a Ctrl+C during its imports
                proc.start()
            child.close()
            self._conns.append(parent)
            self._procs.append(proc)
        try:
            for i in range(num_workers):
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

    def submit(self, requests: Sequence[CollectRequest]) -> None:
        """See :meth:`WorkerPool.submit`."""
        for conn, request in zip(self._conns, requests, strict=True):
            conn.send(("collect", request))

    def gather(self) -> list[RoundResult]:
        """See :meth:`WorkerPool.gather`."""
        return [self._recv(i) for i in range(self.num_workers)]

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
                log.warning("worker %s did not stop; terminating it", proc.name)
                proc.terminate()
                proc.join(timeout=5)
        for conn in self._conns:
            conn.close()


def make_pool(
    config: TrainConfig,
    env_factory: EnvFactory,
    num_workers: int,
    subprocess: bool | None = None,
    ray_address: str | None = None,
    use_ray: bool = False,
) -> WorkerPool:
    """A pool of ``num_workers`` workers: Ray actors with ``use_ray``/``ray_address``, else
    local processes (in this process for one worker unless ``subprocess``).

    Raises:
        ValueError: if ``num_workers`` < 1.
    """
    if num_workers <= 0:
        raise ValueError(f"num_workers must be > 0, got {num_workers}")
    if use_ray or ray_address:
        from explaindrive.agent.ray_pool import RayPool

        return RayPool(config, env_factory, num_workers, ray_address)
    use_procs = num_workers > 1 if subprocess is None else subprocess
    if use_procs:
        return ProcessPool(config, env_factory, num_workers)
    return InProcessPool(config, env_factory, num_workers)
