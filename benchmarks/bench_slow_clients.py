"""``explaindrive serve`` under a flood of slow clients: are normal requests still answered?

Starts the real server with a limit of ``--nofile`` open files (``ulimit -n``), then opens
``--clients`` connections that send a request head one header line per second and
reconnect whenever the server closes them (a "slowloris" flood). Meanwhile a probe sends
a normal ``GET /api/status`` on a fresh connection every half second. Printed: the
probe's answer times and failures, how often the server closed a slow client, the size
of the server's log, its CPU share and its peak memory, each next to its target.

    python benchmarks/bench_slow_clients.py [--clients 1100] [--seconds 30] [--nofile 1024]

Targets: every probe answered, the slowest within 3 s; the log under 5 MB.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import resource
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HEAD = b"GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n"
PROBE = b"GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n"
TARGET_SLOWEST_S = 3.0
TARGET_LOG_BYTES = 5_000_000


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def start_server(port: int, nofile: int, log_path: Path) -> subprocess.Popen[bytes]:
    def limit_files() -> None:
        _soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        resource.setrlimit(resource.RLIMIT_NOFILE, (nofile, hard))

    cmd = [sys.executable, "-m", "explaindrive.cli.main", "serve", "--port", str(port)]
    with log_path.open("wb") as log:
        return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, preexec_fn=limit_files)


async def probe_once(port: int, timeout_s: float = 10.0) -> float | None:
    """Seconds to a complete ``200`` answer on a fresh connection, or ``None``."""
    t0 = time.perf_counter()
    try:
        async with asyncio.timeout(timeout_s):
            reader, writer = await asyncio.open_connection("127.0.0.1", port)
            writer.write(PROBE)
            answer = await reader.read()
            writer.close()
    except (OSError, TimeoutError):
        return None
    return time.perf_counter() - t0 if answer.startswith(b"HTTP/1.1 200") else None


async def wait_until_up(port: int, proc: subprocess.Popen[bytes], timeout_s: float) -> None:
    end = time.monotonic() + timeout_s
    while await probe_once(port, 2.0) is None:
        if proc.poll() is not None or time.monotonic() > end:
            raise SystemExit("the server did not start")
        await asyncio.sleep(0.5)


async def slow_client(port: int, stop: asyncio.Event, closed: list[int]) -> None:
    """Send a header line a second; reconnect when the server closes the connection."""
    while not stop.is_set():
        try:
            reader, writer = await asyncio.open_connection("127.0.0.1", port)
            writer.write(HEAD)
            while not stop.is_set():
                await asyncio.sleep(1.0)
                writer.write(b"X-Slow: 1\r\n")
                await writer.drain()
                if reader.at_eof():
                    break
            writer.close()
        except OSError:
            pass
        closed[0] += 1
        await asyncio.sleep(0.2)


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def peak_rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return float("nan")


async def flood(port: int, clients: int, seconds: float) -> tuple[list[float | None], int]:
    stop = asyncio.Event()
    closed = [0]
    tasks = [asyncio.create_task(slow_client(port, stop, closed)) for _ in range(clients)]
    await asyncio.sleep(3.0)  # let the flood build up
    probes: list[float | None] = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        probes.append(await probe_once(port))
        await asyncio.sleep(0.5)
    stop.set()
    await asyncio.gather(*tasks, return_exceptions=True)
    return probes, closed[0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=1100)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--nofile", type=int, default=1024)
    args = parser.parse_args()
    _soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))  # this side holds the flood
    port = free_port()
    with tempfile.TemporaryDirectory() as tmp:
        log_path = Path(tmp) / "serve.log"
        proc = start_server(port, args.nofile, log_path)
        try:
            asyncio.run(wait_until_up(port, proc, 120.0))
            cpu0, t0 = cpu_seconds(proc.pid), time.monotonic()
            probes, closed = asyncio.run(flood(port, args.clients, args.seconds))
            cpu_share = (cpu_seconds(proc.pid) - cpu0) / (time.monotonic() - t0)
            rss = peak_rss_mb(proc.pid)
            alive = proc.poll() is None
        finally:
            proc.terminate()
            proc.wait(30)
        log_bytes = log_path.stat().st_size
        tail = log_path.read_text(errors="replace").splitlines()[-5:]
    answered = [p for p in probes if p is not None]
    slowest = max(answered) if answered else float("inf")
    print(f"slow clients: {args.clients}, server open-files limit: {args.nofile}")
    print(f"probes answered: {len(answered)}/{len(probes)}; server alive: {alive}")
    if answered:
        print(
            f"answer time [s]: median {statistics.median(answered):.3f}, "
            f"slowest {slowest:.3f} (target <= {TARGET_SLOWEST_S}, "
            f"ratio {slowest / TARGET_SLOWEST_S:.2f})"
        )
    print(f"slow connections closed by the server (or refused): {closed}")
    print(
        f"server log: {log_bytes} B (target < {TARGET_LOG_BYTES}, "
        f"ratio {log_bytes / TARGET_LOG_BYTES:.4f}); last lines: {tail}"
    )
    print(f"server CPU share during the flood: {cpu_share:.2f}; peak RSS {rss:.0f} MB")


if __name__ == "__main__":
    main()
