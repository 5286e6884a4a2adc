"""How ``explaindrive serve`` runs the app: uvicorn, with limits a flood of clients cannot
break.

uvicorn closes idle keep-alive connections (``timeout_keep_alive``) and answers 503 past
``limit_concurrency``, but it waits forever for a request that arrives one byte at a time,
and a process out of file descriptors spins on ``accept()`` and logs a traceback each
time. This module adds what it lacks, as its own HTTP protocol class
(:func:`guarded_protocol`) and a logging filter (:class:`RateLimitFilter`):

- at most :func:`connection_budget` open connections, below the process's limit on open
  files, so ``accept()`` never runs out of them; when the server is full, the connection
  that has waited longest for its request is closed to make room for a new one (if none
  is waiting, the new one is closed), so a request sent in one go is still answered;
- a connection must send a complete request head within ``header_timeout_s`` of opening,
  or of its previous response;
- a WebSocket handshake the app refuses (:class:`~explaindrive.web.guard.RequestGuard`
  answers it with an HTTP status) is logged as one INFO line, without uvicorn's spurious
  ERROR "returned without completing handshake" (:class:`RefusableWebSocketProtocol`);
- a log message repeats at most ``log_lines`` times in ``log_window_s`` (tracebacks only
  the first time); the next line that gets through says how many were dropped.

The figures, and the script that measures them under 1,100 slow clients, are in
docs/web.md.
"""

from __future__ import annotations

import asyncio
import logging
import resource
import time
from dataclasses import dataclass
from typing import Any

import h11
import uvicorn
from uvicorn.protocols.http.h11_impl import H11Protocol
from uvicorn.protocols.websockets.websockets_sansio_impl import WebSocketsSansIOProtocol

log = logging.getLogger(__name__)

FD_RESERVE = 160  # open files kept free of connections: models, SUMO, logs, an accept burst
UVICORN_LOGGERS = ("uvicorn", "uvicorn.error", "uvicorn.access", "asyncio")
WS_LIBRARY_LOGGER = f"{__name__}.websockets"  # the websockets library's lines per connection


@dataclass(frozen=True)
class ServerLimits:
    """What the server holds open, and for how long."""

    max_connections: int = 512
    """Open connections at most (lowered to fit the open-files limit, see
    :func:`connection_budget`); WebSocket streams count."""
    header_timeout_s: float = 5.0
    """[s] Time a connection has to send a complete request head."""
    keep_alive_s: int = 5
    """[s] An idle keep-alive connection is closed after this long (uvicorn's setting)."""
    log_lines: int = 5
    """Lines of one log message let through in each window."""
    log_window_s: float = 60.0
    """[s] The window of :attr:`log_lines`."""


def connection_budget(limits: ServerLimits) -> int:
    """The connections the server keeps open at most: ``limits.max_connections``, or the
    soft limit on open files less :data:`FD_RESERVE` if that is lower (at least 8)."""
    soft, _hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft == resource.RLIM_INFINITY:
        return limits.max_connections
    return max(8, min(limits.max_connections, soft - FD_RESERVE))


def guarded_protocol(max_connections: int, header_timeout_s: float) -> type[H11Protocol]:
    """uvicorn's h11 protocol with a request-head timeout and a bounded connection count."""

    class GuardedH11Protocol(H11Protocol):
        waiting_since = 0.0  # loop time the connection began waiting for a request head
        head_timer: asyncio.TimerHandle | None = None

        def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
            super().connection_made(transport)
            self._wait_for_head()
            if len(self.connections) > max_connections:
                self._make_room()

        def connection_lost(self, exc: Exception | None) -> None:
            if self.head_timer is not None:
                self.head_timer.cancel()
            super().connection_lost(exc)

        def on_response_complete(self) -> None:
            super().on_response_complete()
            self._wait_for_head()

        def waiting(self) -> bool:
            """Open, and no request head received since it opened or last answered."""
            cycle = self.cycle
            return (
                self in self.connections
                and not self.transport.is_closing()
                and self.conn.their_state is h11.IDLE
                and (cycle is None or cycle.response_complete)
            )

        def _wait_for_head(self) -> None:
            if self.head_timer is not None:
                self.head_timer.cancel()
            self.waiting_since = self.loop.time()
            self.head_timer = self.loop.call_later(header_timeout_s, self._head_deadline)

        def _head_deadline(self) -> None:
            if self.waiting():
                self.transport.close()

        def _make_room(self) -> None:
            """Close the connection that has waited longest for its request, else this one."""
            waiting = [
                c
                for c in self.connections
                if isinstance(c, GuardedH11Protocol) and c is not self and c.waiting()
            ]
            victim = min(waiting, key=lambda c: c.waiting_since) if waiting else self
            victim.transport.close()
            self.connections.discard(victim)  # its file closes with the next loop turn

    return GuardedH11Protocol


class RefusableWebSocketProtocol(WebSocketsSansIOProtocol):
    """uvicorn's WebSocket protocol, for which an HTTP answer to the handshake (a refusal)
    completes it. uvicorn logs the refusal at INFO, then, as if the app had sent nothing,
    an ERROR, and the websockets library logs it a second time at INFO; this class keeps
    uvicorn's INFO line only (the library's own lines go to :data:`WS_LIBRARY_LOGGER`)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.conn.logger = logging.getLogger(WS_LIBRARY_LOGGER)

    async def send(self, message: Any) -> None:
        """Send ``message``; the last body part of an HTTP answer ends the handshake."""
        await super().send(message)
        if message["type"] == "websocket.http.response.body" and not message.get("more_body"):
            self.handshake_complete = True


class RateLimitFilter(logging.Filter):
    """Lets each log message (logger and format string) through at most ``lines`` times
    per ``window_s``, with its traceback only the first time; the next line let through
    after a drop says how many were dropped.

    Args:
        lines: lines of one message per window.
        window_s: the window [s].
        max_keys: messages tracked at once (the oldest window is forgotten past this).
    """

    def __init__(self, lines: int, window_s: float, max_keys: int = 1_000) -> None:
        super().__init__()
        self.lines, self.window_s, self.max_keys = lines, window_s, max_keys
        self._seen: dict[tuple[str, str], list[float]] = {}  # key -> [start, shown, dropped]

    def filter(self, record: logging.LogRecord) -> bool:
        """Whether ``record`` is written (it may be shortened)."""
        key = (record.name, str(record.msg))
        now = time.monotonic()
        state = self._seen.get(key)
        if state is None or now - state[0] >= self.window_s:
            dropped = int(state[2]) if state is not None else 0
            if state is None and len(self._seen) >= self.max_keys:
                self._seen.pop(next(iter(self._seen)))
            self._seen[key] = [now, 1.0, 0.0]
            if dropped:
                record.msg = f"{record.msg} [{dropped} similar lines dropped]"
            return True
        if state[1] >= self.lines:
            state[2] += 1
            return False
        state[1] += 1
        record.exc_info, record.exc_text, record.stack_info = None, None, None
        return True


def rate_limit_logs(limits: ServerLimits, loggers: tuple[str, ...] = UVICORN_LOGGERS) -> None:
    """Add a :class:`RateLimitFilter` to every handler of the root logger and of
    ``loggers`` (a root logger without handlers gets one on stderr first)."""
    root = logging.getLogger()
    if not root.handlers:
        logging.basicConfig(format="%(levelname)s %(name)s: %(message)s")
    shared = RateLimitFilter(limits.log_lines, limits.log_window_s)
    for name in ("", *loggers):
        for handler in logging.getLogger(name).handlers:
            if not any(isinstance(f, RateLimitFilter) for f in handler.filters):
                handler.addFilter(shared)


def server_config(app: Any, host: str, port: int, limits: ServerLimits) -> uvicorn.Config:
    """The uvicorn config of :func:`run_server` (logging is set up when it is made)."""
    budget = connection_budget(limits)
    return uvicorn.Config(
        app,
        host=host,
        port=port,
        log_level="warning",
        http=guarded_protocol(budget, limits.header_timeout_s),
        ws=RefusableWebSocketProtocol,
        timeout_keep_alive=limits.keep_alive_s,
        limit_concurrency=budget + FD_RESERVE // 2,  # 503 past it; connections stay below
        backlog=256,
    )


def run_server(app: Any, host: str, port: int, limits: ServerLimits | None = None) -> None:
    """Serve ``app`` on ``host:port`` until Ctrl+C or SIGTERM, within ``limits``."""
    limits = limits or ServerLimits()
    config = server_config(app, host, port, limits)
    rate_limit_logs(limits)
    log.info("serving at most %d connections", connection_budget(limits))
    uvicorn.Server(config).run()
