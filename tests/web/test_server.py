"""The server's limits: connection budget, room made for new clients, refused WebSockets
logged once, and the log's rate limit."""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections.abc import Iterator

import pytest
import uvicorn
from starlette.types import Receive, Scope, Send

from explaindrive.web import server
from explaindrive.web.guard import RequestGuard
from explaindrive.web.server import (
    FD_RESERVE,
    RateLimitFilter,
    ServerLimits,
    connection_budget,
    server_config,
)


@pytest.mark.parametrize(
    ("soft", "max_connections", "budget"),
    [
        (1024, 512, 512),  # the configured limit fits
        (1024, 2000, 1024 - FD_RESERVE),  # lowered to fit the open-files limit: 864
        (100, 512, 8),  # never below 8
    ],
)
def test_the_connection_budget_fits_the_open_files_limit(
    monkeypatch: pytest.MonkeyPatch, soft: int, max_connections: int, budget: int
) -> None:
    monkeypatch.setattr(server.resource, "getrlimit", lambda _which: (soft, 4096))
    assert connection_budget(ServerLimits(max_connections=max_connections)) == budget


def record(msg: str, exc: bool = False) -> logging.LogRecord:
    exc_info = (ValueError, ValueError("bad fd"), None) if exc else None
    return logging.LogRecord("asyncio", logging.ERROR, "x.py", 1, msg, None, exc_info)


def test_a_repeated_log_line_is_let_through_a_few_times_per_window(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    clock = [100.0]
    monkeypatch.setattr(server.time, "monotonic", lambda: clock[0])
    limit = RateLimitFilter(lines=2, window_s=60.0)
    records = [record("accept failed", exc=True) for _ in range(5)]
    assert [limit.filter(r) for r in records] == [True, True, False, False, False]
    assert records[0].exc_info is not None and records[1].exc_info is None  # one traceback
    assert limit.filter(record("another message"))  # counted apart
    clock[0] += 60.0  # a new window: the first line says what was dropped
    again = record("accept failed")
    assert limit.filter(again)
    assert again.getMessage() == "accept failed [3 similar lines dropped]"


def test_the_filter_forgets_the_oldest_message_past_its_key_limit() -> None:
    limit = RateLimitFilter(lines=1, window_s=60.0, max_keys=2)
    assert [limit.filter(record(m)) for m in ("a", "b", "a", "c", "a")] == [
        True,  # a
        True,  # b
        False,  # a again in its window
        True,  # c: a is forgotten
        True,  # a: new again
    ]


async def hello(scope: Scope, receive: Receive, send: Send) -> None:
    """A tiny app: ``200 hello`` for HTTP; WebSockets never get past the guard here."""
    if scope["type"] == "lifespan":
        return
    await send({"type": "http.response.start", "status": 200, "headers": []})
    await send({"type": "http.response.body", "body": b"hello"})


@pytest.fixture
def small_server(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[int, list[logging.LogRecord]]]:
    """The server of ``explaindrive serve`` with room for 8 connections (the least it keeps),
    on a free port; also the records its ``uvicorn.error`` logger wrote at INFO and above."""
    monkeypatch.setattr(server.resource, "getrlimit", lambda _which: (8 + FD_RESERVE, 4096))
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = int(s.getsockname()[1])
    app = RequestGuard(hello, hosts={"127.0.0.1"}, body_limit=lambda _path: 1_000)
    config = server_config(app, "127.0.0.1", port, ServerLimits(header_timeout_s=600.0))
    seen: list[logging.LogRecord] = []
    handler = logging.Handler()
    handler.emit = seen.append  # type: ignore[assignment]
    error_log = logging.getLogger("uvicorn.error")
    error_log.addHandler(handler)
    error_log.setLevel(logging.INFO)
    srv = uvicorn.Server(config)
    thread = threading.Thread(target=srv.run, daemon=True)
    thread.start()
    while not srv.started:
        assert thread.is_alive(), "the server did not start"
        time.sleep(0.05)
    yield port, seen
    srv.should_exit = True
    thread.join(15)
    error_log.removeHandler(handler)


def closed_by_server(conn: socket.socket) -> bool:
    conn.settimeout(10)
    try:
        return conn.recv(100) == b""
    except ConnectionResetError:
        return True


def get(port: int) -> bytes:
    with socket.create_connection(("127.0.0.1", port), timeout=10) as conn:
        conn.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")
        return b"".join(iter(lambda: conn.recv(4096), b""))


def test_a_full_server_closes_the_longest_waiting_connection_for_a_new_one(
    small_server: tuple[int, list[logging.LogRecord]],
) -> None:
    port, _seen = small_server
    slow = []
    for _ in range(8):  # fill the server with clients that never finish their request
        conn = socket.create_connection(("127.0.0.1", port))
        conn.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n")
        slow.append(conn)
        time.sleep(0.1)  # opened in this order
    answer = get(port)  # a ninth, sent in one go
    assert answer.startswith(b"HTTP/1.1 200") and b"\r\nhello\r\n" in answer
    assert closed_by_server(slow[0])  # the first slow client made room
    slow[1].settimeout(0.5)
    with pytest.raises(TimeoutError):
        slow[1].recv(100)  # still open, still waiting
    for conn in slow:
        conn.close()


def test_a_refused_websocket_is_logged_once_at_info(
    small_server: tuple[int, list[logging.LogRecord]],
) -> None:
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect
    from websockets.typing import Origin

    port, seen = small_server
    seen.clear()  # the start-up lines
    with pytest.raises(InvalidStatus, match="HTTP 403"):
        connect(f"ws://127.0.0.1:{port}/ws", origin=Origin("http://elsewhere.example")).close()
    time.sleep(0.3)  # uvicorn's spurious ERROR came after the app returned
    assert [r.levelname for r in seen] == ["INFO"]
    assert seen[0].getMessage().endswith('"WebSocket /ws" 403')
