"""Checks at the door of the web app, before any route runs.

- ``Host`` must name the server (loopback names by default): a page of another site
  that rebinds its DNS name to 127.0.0.1 is answered 400.
- Requests that change state (every method but GET, HEAD and OPTIONS) and the
  WebSocket handshake must come from the server's own page: an ``Origin`` that is not
  the server's, or ``Sec-Fetch-Site: cross-site``/``same-site``, is answered 403. A
  request without ``Origin`` is a non-browser client (curl, a script) and passes.
- Request bodies are counted while they stream in: a declared ``Content-Length`` over
  the limit is answered 413 before the body is read, and a body that grows past it
  (chunked, without a length) is cut off there and answered 413.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from typing import Any
from urllib.parse import urlsplit

from starlette.datastructures import Headers
from starlette.exceptions import HTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

LOOPBACK_HOSTS: frozenset[str] = frozenset({"127.0.0.1", "localhost", "::1"})
WILDCARD_HOSTS: frozenset[str] = frozenset({"0.0.0.0", "::", ""})
SAFE_METHODS: frozenset[str] = frozenset({"GET", "HEAD", "OPTIONS"})
SAME_ORIGIN_FETCH_SITES: frozenset[str] = frozenset({"same-origin", "none"})

BodyLimit = Callable[[str], int]  # request path -> largest accepted body [B]


class BodyTooLargeError(HTTPException):
    """A request body passed the limit while it was being read (HTTP 413)."""

    def __init__(self, limit_bytes: int) -> None:
        # the rest of the body is never read: the connection cannot be reused
        super().__init__(
            413, f"the request body exceeds {limit_bytes} bytes", headers={"connection": "close"}
        )


def served_hosts(bind_host: str, extra: Iterable[str] = ()) -> frozenset[str]:
    """The host names the server answers to.

    Args:
        bind_host: the address the server binds (``--host``); a loopback address serves
            the loopback names, a wildcard (``0.0.0.0``, ``::``) the loopback names too,
            any other address or name itself.
        extra: further names the page is opened under (``--allow-host``).
    """
    host = _strip_brackets(bind_host.strip().lower())
    names = set(LOOPBACK_HOSTS) if host in LOOPBACK_HOSTS | WILDCARD_HOSTS else {host}
    names.update(_strip_brackets(name.strip().lower()) for name in extra if name.strip())
    return frozenset(names)


def host_name(host_header: str) -> str:
    """The name part of a ``Host`` header (``[::1]:8000`` -> ``::1``, ``a:80`` -> ``a``)."""
    value = host_header.strip().lower()
    if value.startswith("["):
        return value[1 : value.find("]")] if "]" in value else ""
    return value.rsplit(":", 1)[0] if value.count(":") == 1 else value


def _strip_brackets(name: str) -> str:
    return name[1:-1] if name.startswith("[") and name.endswith("]") else name


def origin_problem(headers: Headers) -> str | None:
    """Why a state-changing request does not come from the server's own page, or ``None``."""
    site = headers.get("sec-fetch-site")
    if site is not None and site.lower() not in SAME_ORIGIN_FETCH_SITES:
        return f"cross-site request refused (Sec-Fetch-Site: {site[:40]})"
    origin = headers.get("origin")
    if origin is None:
        return None
    parts = urlsplit(origin.strip())
    host = headers.get("host", "").strip().lower()
    if parts.scheme not in ("http", "https") or parts.netloc.lower() != host:
        return f"cross-origin request refused (Origin {origin[:80]!r} is not this server)"
    return None


class RequestGuard:
    """ASGI middleware: ``Host`` and ``Origin`` checks and a streaming body-size limit.

    Args:
        app: the application behind the guard.
        hosts: host names the server answers to (see :func:`served_hosts`).
        body_limit: the largest body accepted on a path [B].
    """

    def __init__(self, app: ASGIApp, *, hosts: Iterable[str], body_limit: BodyLimit) -> None:
        self.app = app
        self.hosts = frozenset(_strip_brackets(h.lower()) for h in hosts)
        self.body_limit = body_limit

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Refuse or pass the request on (``lifespan`` passes untouched)."""
        if scope["type"] not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = Headers(scope=scope)
        status, detail = self._refusal(scope, headers)
        if status:
            await _deny(scope, send, status, detail)
            return
        if scope["type"] == "websocket":
            await self.app(scope, receive, send)
            return
        await self._limited(scope, receive, send, headers)

    def _refusal(self, scope: Scope, headers: Headers) -> tuple[int, str]:
        if host_name(headers.get("host", "")) not in self.hosts:
            return 400, "unknown Host; open the page under the address the server was started on"
        if scope["type"] == "websocket" or scope["method"] not in SAFE_METHODS:
            problem = origin_problem(headers)
            if problem is not None:
                return 403, problem
        return 0, ""

    async def _limited(self, scope: Scope, receive: Receive, send: Send, headers: Headers) -> None:
        limit = self.body_limit(scope["path"])
        declared = headers.get("content-length", "")
        if declared.strip().isdigit() and int(declared) > limit:
            await _deny(scope, send, 413, BodyTooLargeError(limit).detail)
            return
        received = 0
        started = False

        async def counting_receive() -> Message:
            nonlocal received
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > limit:
                    raise BodyTooLargeError(limit)
            return message

        async def tracking_send(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, counting_receive, tracking_send)
        except BodyTooLargeError as exc:  # read outside a route's error handling
            if started:
                raise
            await _deny(scope, send, 413, exc.detail)


async def _deny(scope: Scope, send: Send, status: int, detail: str) -> None:
    """Answer ``status`` with ``{"detail": ...}``; a WebSocket handshake is refused."""
    body = json.dumps({"detail": detail}).encode()
    head: list[tuple[bytes, bytes]] = [
        (b"content-type", b"application/json"),
        (b"content-length", str(len(body)).encode()),
    ]
    if scope["type"] == "http":
        head.append((b"connection", b"close"))
        await send({"type": "http.response.start", "status": status, "headers": head})
        await send({"type": "http.response.body", "body": body})
        return
    extensions: dict[str, Any] = scope.get("extensions") or {}
    if "websocket.http.response" in extensions:
        await send({"type": "websocket.http.response.start", "status": status, "headers": head})
        await send({"type": "websocket.http.response.body", "body": body})
    else:  # the server answers 403
        await send({"type": "websocket.close", "code": 1008, "reason": detail[:120]})
