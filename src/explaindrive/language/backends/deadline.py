"""A total deadline for HTTP calls to a model endpoint.

``httpx`` (under the ``openai`` SDK) bounds each connect, read and write on its own: an
endpoint that sends one byte a second never trips a read timeout, and one call could
take as long as the endpoint likes. Here every socket operation of a call is bounded by
the time left until the call's deadline, so a hanging or dripping endpoint costs at most
that deadline: the operation that would pass it raises a timeout instead.

The deadline is per thread (:func:`until`), so calls made at the same time from several
threads (interpretation and explanation) each keep their own, over one connection pool.
Name resolution (``getaddrinfo``) is not bounded; endpoints are expected to be given as
host names that resolve at once (``localhost``) or as addresses.
"""

from __future__ import annotations

import contextlib
import importlib
import sys
import threading
import time
from collections.abc import Iterable, Iterator
from functools import lru_cache
from typing import Any

_local = threading.local()


class DeadlineExceededError(TimeoutError):
    """The endpoint did not answer within the call's total deadline."""


@contextlib.contextmanager
def until(end: float) -> Iterator[None]:
    """Bound every socket operation of this thread by the monotonic time ``end`` [s]."""
    previous = getattr(_local, "end", None)
    _local.end = end
    try:
        yield
    finally:
        _local.end = previous


def _bounded(timeout: float | None, error: type[Exception]) -> float | None:
    """``timeout`` shortened to the time left before this thread's deadline.

    Raises:
        error: (a timeout of the HTTP core library) when the deadline has passed.
    """
    end: float | None = getattr(_local, "end", None)
    if end is None:
        return timeout
    left = end - time.monotonic()
    if left <= 0.0:
        raise error("the call's total deadline has passed")
    return left if timeout is None else min(timeout, left)


def http_modules() -> tuple[Any, Any]:
    """The HTTP client and core libraries the installed ``openai`` SDK builds on:
    ``httpx2`` and ``httpcore2`` in recent releases, ``httpx`` and ``httpcore`` before."""
    import openai  # noqa: F401  (importing the SDK imports its HTTP library)

    client, core = ("httpx2", "httpcore2") if "httpx2" in sys.modules else ("httpx", "httpcore")
    return importlib.import_module(client), importlib.import_module(core)


def _stream_class(httpcore: Any) -> type:
    """A network stream whose every read and write respects the thread's deadline."""
    base: Any = httpcore.NetworkStream

    class DeadlineStream(base):
        def __init__(self, inner: Any) -> None:
            self._inner = inner

        def read(self, max_bytes: int, timeout: float | None = None) -> bytes:
            return bytes(self._inner.read(max_bytes, _bounded(timeout, httpcore.ReadTimeout)))

        def write(self, buffer: bytes, timeout: float | None = None) -> None:
            self._inner.write(buffer, _bounded(timeout, httpcore.WriteTimeout))

        def close(self) -> None:
            self._inner.close()

        def start_tls(
            self, ssl_context: Any, server_hostname: str | None = None, timeout: float | None = None
        ) -> Any:
            bounded = _bounded(timeout, httpcore.ConnectTimeout)
            return DeadlineStream(self._inner.start_tls(ssl_context, server_hostname, bounded))

        def get_extra_info(self, info: str) -> Any:
            return self._inner.get_extra_info(info)

    return DeadlineStream


def _backend_class(httpcore: Any) -> type:
    """Synchronous sockets, connected and used within the thread's deadline."""
    base: Any = httpcore.NetworkBackend
    stream = _stream_class(httpcore)

    class DeadlineBackend(base):
        def __init__(self) -> None:
            self._inner = httpcore.SyncBackend()

        def connect_tcp(
            self,
            host: str,
            port: int,
            timeout: float | None = None,
            local_address: str | None = None,
            socket_options: Iterable[Any] | None = None,
        ) -> Any:
            bounded = _bounded(timeout, httpcore.ConnectTimeout)
            return stream(
                self._inner.connect_tcp(host, port, bounded, local_address, socket_options)
            )

        def connect_unix_socket(
            self, path: str, timeout: float | None = None, socket_options: Any = None
        ) -> Any:
            bounded = _bounded(timeout, httpcore.ConnectTimeout)
            return stream(self._inner.connect_unix_socket(path, bounded, socket_options))

        def sleep(self, seconds: float) -> None:
            self._inner.sleep(seconds)

    return DeadlineBackend


@lru_cache(maxsize=1)
def _transport_class() -> type:
    """The HTTP library's transport over a pool of deadline-bound sockets (built once, over
    the libraries of :func:`http_modules`)."""
    httpx, httpcore = http_modules()
    base: Any = httpx.HTTPTransport
    backend = _backend_class(httpcore)

    class DeadlineTransport(base):
        def __init__(self) -> None:
            super().__init__()
            self._pool = httpcore.ConnectionPool(
                ssl_context=httpx.create_ssl_context(), network_backend=backend()
            )

    return DeadlineTransport


def http_client(timeout_s: float) -> Any:
    """An HTTP client for the ``openai`` SDK whose calls made inside :func:`until` end by
    its deadline.

    Args:
        timeout_s: the longest single connect, read or write [s] (also outside
            :func:`until`).

    Proxies from the environment are not used: the endpoint is reached directly.
    """
    httpx, _ = http_modules()
    return httpx.Client(transport=_transport_class()(), timeout=httpx.Timeout(timeout_s))
