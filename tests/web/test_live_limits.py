"""The limits against a live server in its own process, measured from outside.

The server (``tests/web/serve_fakes.py``) runs with the default limits: 5 MB uploads,
30 s of audio, 16 KiB JSON bodies, loopback names only. Its peak memory (``VmHWM``), CPU
time and bytes written (``wchar``) come from ``/proc``. Run with ``-s`` to see them.
"""

from __future__ import annotations

import http.client
import json
import select
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from explaindrive.web.app import MAX_JSON_BYTES, MAX_UPLOAD_BYTES, MULTIPART_OVERHEAD_BYTES

from .conftest import wav
from .flac import bomb_duration_s, flac_bomb

REPO = Path(__file__).resolve().parents[2]
BOMB_FRAMES = 8000  # 3.0 h of audio in about 110 KB
BOUNDARY = "----explaindrive-test"

pytestmark = pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs /proc")


@dataclass(frozen=True)
class Server:
    """A live server process."""

    pid: int
    port: int

    @property
    def origin(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def request(
        self,
        method: str,
        path: str,
        body: bytes | None = None,
        headers: dict[str, str] | None = None,
    ) -> tuple[int, bytes]:
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        try:
            conn.request(method, path, body=body, headers=headers or {})
            res = conn.getresponse()
            return res.status, res.read()
        finally:
            conn.close()

    def post_json(self, path: str, body: object = None) -> tuple[int, dict]:
        data = json.dumps(body).encode() if body is not None else None
        status, raw = self.request("POST", path, data, {"content-type": "application/json"})
        return status, json.loads(raw)

    def upload(self, data: bytes, content_type: str) -> tuple[int, dict]:
        body, header = multipart(data, content_type)
        status, raw = self.request("POST", "/api/ride/audio", body, {"content-type": header})
        return status, json.loads(raw)

    def proc(self, name: str, field: str) -> int:
        """An integer field of ``/proc/<pid>/<name>`` (``status`` values in kB)."""
        for line in Path(f"/proc/{self.pid}/{name}").read_text().splitlines():
            key, _, value = line.partition(":")
            if key == field:
                return int(value.split()[0])
        raise KeyError(field)

    def peak_rss_mb(self) -> float:
        return self.proc("status", "VmHWM") / 1024

    def cpu_s(self) -> float:
        fields = Path(f"/proc/{self.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / 100  # utime + stime [clock ticks]


def multipart(data: bytes, content_type: str) -> tuple[bytes, str]:
    head = (
        f'--{BOUNDARY}\r\nContent-Disposition: form-data; name="file"; filename="a"\r\n'
        f"Content-Type: {content_type}\r\n\r\n"
    ).encode()
    return (
        head + data + f"\r\n--{BOUNDARY}--\r\n".encode(),
        f"multipart/form-data; boundary={BOUNDARY}",
    )


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    port = _free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "tests.web.serve_fakes", str(port)],
        cwd=REPO,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    srv = Server(proc.pid, port)
    end = time.monotonic() + 60
    while True:
        assert proc.poll() is None and time.monotonic() < end, "the server did not start"
        try:
            if srv.request("GET", "/api/status")[0] == 200:
                break
        except OSError:
            time.sleep(0.1)
    yield srv
    proc.terminate()
    try:
        proc.wait(15)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


@pytest.fixture
def paused_ride(server: Server) -> Iterator[Server]:
    """A started, paused ride (audio uploads are accepted, no steps use the CPU)."""
    assert server.post_json("/api/ride/start", {"max_steps": 600})[0] == 200
    assert server.post_json("/api/ride/pause")[0] == 200
    yield server
    server.post_json("/api/ride/reset")


@pytest.mark.parametrize("declare_length", [False, True])
def test_flac_bomb_is_refused_with_memory_bounded(
    paused_ride: Server, declare_length: bool
) -> None:
    srv = paused_ride
    assert srv.upload(wav(2.0), "audio/wav")[0] == 202  # decoder code and buffers warmed up
    bomb = flac_bomb(BOMB_FRAMES, declare_length=declare_length)
    assert len(bomb) < 120_000 and bomb_duration_s(BOMB_FRAMES) > 3 * 3600
    rss0, cpu0 = srv.peak_rss_mb(), srv.cpu_s()
    status, answer = srv.upload(bomb, "audio/flac")
    rss1, cpu1 = srv.peak_rss_mb(), srv.cpu_s()
    print(
        f"\nFLAC bomb ({len(bomb)} B, {bomb_duration_s(BOMB_FRAMES) / 3600:.1f} h, length "
        f"{'declared' if declare_length else 'not declared'}): HTTP {status}; server peak "
        f"RSS {rss0:.0f} -> {rss1:.0f} MB, CPU {cpu1 - cpu0:.2f} s"
    )
    assert status == 413 and "longer than 30 s" in answer["detail"]
    assert rss1 - rss0 < 20.0  # [MB] decoding it whole at 16 kHz float32 would need 690 MB
    assert cpu1 - cpu0 < 2.0  # [s]


def test_a_50_mb_json_body_gets_a_short_answer(server: Server) -> None:
    rss0 = server.peak_rss_mb()
    with socket.create_connection(("127.0.0.1", server.port), timeout=30) as sock:
        sock.sendall(
            b"POST /api/ride/say HTTP/1.1\r\nHost: 127.0.0.1\r\n"
            b"Content-Type: application/json\r\nContent-Length: 50000000\r\n\r\n"
        )
        sent = _send_until_answered(sock, b'{"text": "' + b"x" * 65_000, 50_000_000)
        answer = _read_all(sock)
    print(f"\n50 MB JSON body: answered after {sent} B sent: {answer!r}")
    assert answer.startswith(b"HTTP/1.1 413 ")
    _, _, body = answer.partition(b"\r\n\r\n")
    assert json.loads(body) == {"detail": f"the request body exceeds {MAX_JSON_BYTES} bytes"}
    assert len(answer) < 300 and server.peak_rss_mb() - rss0 < 20.0


def test_a_chunked_upload_is_cut_off_at_the_limit(paused_ride: Server) -> None:
    """No Content-Length: the server stops reading at the limit instead of spooling it all."""
    srv = paused_ride
    limit = MAX_UPLOAD_BYTES + MULTIPART_OVERHEAD_BYTES
    written0 = srv.proc("io", "wchar")
    with socket.create_connection(("127.0.0.1", srv.port), timeout=30) as sock:
        sock.sendall(
            b"POST /api/ride/audio HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\n"
            + f"Content-Type: multipart/form-data; boundary={BOUNDARY}\r\n\r\n".encode()
        )
        part = multipart(b"", "audio/wav")[0].split(b"\r\n--")[0] + b"RIFF"
        sock.sendall(f"{len(part):x}\r\n".encode() + part + b"\r\n")
        sent = _send_until_answered(sock, bytes(65_536), 64 * 2**20, chunked=True)
        answer = _read_all(sock)
    written = srv.proc("io", "wchar") - written0
    print(f"\nchunked upload: answered after {sent} B sent; the server wrote {written} B")
    assert answer.startswith(b"HTTP/1.1 413 ") and f"exceeds {limit} bytes".encode() in answer
    assert sent < 64 * 2**20  # cut off long before the end of the stream
    assert written < limit + 2**20  # [B] at most the limit reached the disk


def test_cross_origin_post_and_websocket_are_refused(server: Server) -> None:
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    status, raw = server.request(
        "POST", "/api/ride/start", b"{}", {"origin": "http://evil.example"}
    )
    assert status == 403 and b"refused" in raw
    assert json.loads(server.request("GET", "/api/status")[1])["state"] == "idle"
    with pytest.raises(InvalidStatus) as denied:
        connect(f"ws://127.0.0.1:{server.port}/ws", origin="http://evil.example")
    assert denied.value.response.status_code == 403
    with connect(f"ws://127.0.0.1:{server.port}/ws", origin=server.origin) as ws:
        assert json.loads(ws.recv(timeout=10))["type"] == "snapshot"
    status, _ = server.request("GET", "/api/status", headers={"host": "rebound.example:80"})
    assert status == 400


def _send_until_answered(
    sock: socket.socket, chunk: bytes, total: int, chunked: bool = False
) -> int:
    """Send ``chunk`` repeatedly (up to ``total`` bytes) until the server answers or closes."""
    sent = 0
    while sent < total:
        readable, _, _ = select.select([sock], [], [], 0)
        if readable:
            break
        data = f"{len(chunk):x}\r\n".encode() + chunk + b"\r\n" if chunked else chunk
        try:
            sock.sendall(data)
        except (BrokenPipeError, ConnectionResetError):
            break
        sent += len(chunk)
    return sent


def _read_all(sock: socket.socket) -> bytes:
    out = b""
    try:
        while data := sock.recv(65_536):
            out += data
    except (ConnectionResetError, TimeoutError):
        pass
    return out
