"""Session fixtures: models are loaded once; a scripted OpenAI-compatible server."""

from __future__ import annotations

import contextlib
import json
import shutil
import subprocess
import threading
import time
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest

from explaindrive.language.backends.embedded import EmbeddedIntentInterpreter
from explaindrive.language.speech.transcriber import Transcriber


@pytest.fixture(scope="session")
def interpreter() -> EmbeddedIntentInterpreter:
    """The default embedded LLM-1 (MiniLM), its encoder loaded once for the whole session."""
    it = EmbeddedIntentInterpreter()
    it.load()
    return it


@pytest.fixture(scope="session")
def transcriber() -> Transcriber:
    """Whisper tiny.en, loaded once."""
    t = Transcriber()
    t.load()
    return t


@pytest.fixture(scope="session")
def speak(tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    """Synthesise a WAV file with espeak-ng (skips if espeak-ng is not installed)."""
    exe = shutil.which("espeak-ng")
    if exe is None:
        pytest.skip("espeak-ng is not installed (apt-get install espeak-ng)")
    root = tmp_path_factory.mktemp("speech")

    def _speak(text: str, name: str) -> Path:
        out = root / f"{name}.wav"
        subprocess.run([exe, "-s", "150", "-w", str(out), text], check=True)
        return out

    return _speak


def chat_completion(text: str, model: str) -> bytes:
    """The JSON body of an OpenAI chat completion whose one choice says ``text``."""
    message = {"role": "assistant", "content": text}
    return json.dumps(
        {
            "id": f"chatcmpl-{model}",
            "object": "chat.completion",
            "created": 0,
            "model": model,
            "choices": [{"index": 0, "finish_reason": "stop", "message": message}],
        }
    ).encode()


class LocalChatServer:
    """An OpenAI-compatible address on 127.0.0.1 (a free port), served by a thread.

    Every POST body is recorded in ``bodies``, then :meth:`answer` replies.
    """

    def __init__(self) -> None:
        self.bodies: list[dict[str, Any]] = []
        outer = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: Any) -> None:
                pass

            def do_POST(self) -> None:
                length = int(self.headers.get("Content-Length", "0"))
                outer.bodies.append(json.loads(self.rfile.read(length) or b"{}"))
                outer.answer(self)

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.server.daemon_threads = True
        self.base_url = f"http://127.0.0.1:{self.server.server_address[1]}/v1"
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()

    def answer(self, handler: BaseHTTPRequestHandler) -> None:
        """Reply to the request ``handler`` has just read."""
        raise NotImplementedError

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


class ScriptedOpenAI(LocalChatServer):
    """A chat endpoint that replays scripted answers.

    Each entry of ``script`` is ``("ok", text)``, ``("slow", seconds, text)`` or
    ``("http", status)``; the last entry repeats. ``requests`` holds every request body.
    """

    def __init__(self) -> None:
        self.script: list[tuple[Any, ...]] = [("ok", "[EXPLAIN]")]
        super().__init__()
        self.requests = self.bodies

    def answer(self, handler: BaseHTTPRequestHandler) -> None:
        step = self.script.pop(0) if len(self.script) > 1 else self.script[0]
        if step[0] == "http":
            body = json.dumps({"error": {"message": "scripted failure"}}).encode()
            handler.send_response(step[1])
        else:
            if step[0] == "slow":
                time.sleep(step[1])
            body = chat_completion(step[-1], "scripted")
            handler.send_response(200)
        handler.send_header("Content-Type", "application/json")
        handler.send_header("Content-Length", str(len(body)))
        handler.end_headers()
        with contextlib.suppress(BrokenPipeError):  # the client timed out first
            handler.wfile.write(body)


@pytest.fixture()
def openai_server() -> Iterator[ScriptedOpenAI]:
    """A scripted OpenAI-compatible HTTP server started by the test on 127.0.0.1."""
    srv = ScriptedOpenAI()
    yield srv
    srv.close()


class MisbehavingEndpoint(LocalChatServer):
    """A chat endpoint that never answers in time.

    ``mode="hang"`` reads the request and sends nothing; ``mode="drip"`` sends a valid
    HTTP response (status line, headers and a chat completion) one byte every
    ``interval_s`` seconds. ``bodies`` records every request body.
    """

    def __init__(self, mode: str, interval_s: float = 1.0) -> None:
        if mode not in ("hang", "drip"):
            raise ValueError(f"unknown mode {mode!r}")
        self.mode = mode
        self.interval_s = interval_s
        self._closed = threading.Event()
        super().__init__()

    def answer(self, handler: BaseHTTPRequestHandler) -> None:
        if self.mode == "hang":
            self._closed.wait(60.0)
            return
        body = chat_completion("You want me to drive faster, is this correct?", "drip")
        head = (
            "HTTP/1.1 200 OK\r\nContent-Type: application/json\r\n"
            f"Content-Length: {len(body)}\r\n\r\n"
        ).encode()
        reply = head + body
        for i in range(len(reply)):
            if self._closed.wait(self.interval_s):
                return
            try:
                handler.wfile.write(reply[i : i + 1])
                handler.wfile.flush()
            except OSError:  # the client gave up
                return

    @property
    def requests(self) -> int:
        """Requests received so far."""
        return len(self.bodies)

    def said(self) -> list[str]:
        """The user message of every request."""
        return [b["messages"][-1]["content"] for b in self.bodies]

    def close(self) -> None:
        self._closed.set()
        super().close()


@pytest.fixture(params=["hang", "drip"])
def bad_endpoint(request: pytest.FixtureRequest) -> Iterator[MisbehavingEndpoint]:
    """An endpoint that hangs, then one that drips a byte a second (each test runs twice)."""
    srv = MisbehavingEndpoint(request.param)
    yield srv
    srv.close()
