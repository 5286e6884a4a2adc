"""Memory of ``explaindrive serve`` as its models load: started, first ride, first recording.

Starts the real server (shipped policies, embedded language backend), then prints its
resident memory (RSS) and peak (VmHWM) at three moments:

1. started: the page and the API answer; no model is loaded yet;
2. after ``POST /api/ride/start``: the driving policies and the intent model are loaded
   (the first start pays for them; later rides reuse them);
3. after ``POST /api/ride/audio`` and its transcript: Whisper is loaded too.

    python scripts/serve_memory.py [--wait 20]
"""

from __future__ import annotations

import argparse
import io
import json
import socket
import subprocess
import sys
import time
import urllib.request
import wave
from pathlib import Path

import numpy as np


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def memory_mb(pid: int) -> tuple[float, float]:
    """(RSS, peak RSS) of ``pid`` [MB]."""
    fields = {}
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        key, _, value = line.partition(":")
        fields[key] = value.split()
    return int(fields["VmRSS"][0]) / 1024, int(fields["VmHWM"][0]) / 1024


def report(moment: str, pid: int) -> None:
    rss, peak = memory_mb(pid)
    print(f"{moment:<17} RSS {rss:.0f} MB, peak {peak:.0f} MB")


def call(url: str, data: bytes | None = None, content_type: str = "application/json") -> dict:
    request = urllib.request.Request(url, data=data, headers={"Content-Type": content_type})
    with urllib.request.urlopen(request, timeout=300) as answer:
        return json.loads(answer.read())


def tone_wav(seconds: float = 2.0, rate_hz: int = 16_000) -> bytes:
    t = np.arange(int(seconds * rate_hz)) / rate_hz
    samples = (8000 * np.sin(2 * np.pi * 220.0 * t)).astype("<i2")
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(rate_hz)
        out.writeframes(samples.tobytes())
    return buffer.getvalue()


def multipart(field: str, name: str, data: bytes, content_type: str) -> tuple[bytes, str]:
    boundary = "explaindrive-memory"
    head = (
        f'--{boundary}\r\nContent-Disposition: form-data; name="{field}"; filename="{name}"\r\n'
        f"Content-Type: {content_type}\r\n\r\n"
    ).encode()
    return (
        head + data + f"\r\n--{boundary}--\r\n".encode(),
        f"multipart/form-data; boundary={boundary}",
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wait", type=float, default=20.0, help="[s] after each step")
    args = parser.parse_args()
    port = free_port()
    base = f"http://127.0.0.1:{port}"
    cmd = [sys.executable, "-m", "explaindrive.cli.main", "serve", "--port", str(port)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        end = time.monotonic() + 120
        while True:
            try:
                call(f"{base}/api/status")
                break
            except OSError:
                assert proc.poll() is None and time.monotonic() < end, "the server did not start"
                time.sleep(0.5)
        report("started:", proc.pid)
        call(f"{base}/api/ride/start", json.dumps({"command": "comfort"}).encode())
        time.sleep(args.wait)
        report("first ride:", proc.pid)
        body, content_type = multipart("file", "line.wav", tone_wav(), "audio/wav")
        call(f"{base}/api/ride/audio", body, content_type)
        time.sleep(args.wait)
        report("first recording:", proc.pid)
    finally:
        proc.terminate()
        proc.wait(30)


if __name__ == "__main__":
    main()
