"""The passenger web app: a FastAPI back end, a WebSocket stream and a static page.

Endpoints (all JSON unless noted):

- ``GET /``: the page; ``GET /static/...``: its script and style sheet.
- ``GET /api/scene``: the road network to draw (lanes, crossings, signal heads).
- ``GET /api/status``: ride state, settings, pending confirmation question.
- ``POST /api/ride/start`` (:class:`StartRequest`), ``/pause``, ``/resume``, ``/reset``.
- ``POST /api/ride/say`` (:class:`SayRequest`): a typed passenger line.
- ``POST /api/ride/audio`` (multipart, field ``file``): a recorded passenger line.
- ``POST /api/ride/answer`` (:class:`AnswerRequest`): yes/no to the question.
- ``WS /ws``: a snapshot, then a frame per step and a status message per change.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import AsyncIterator, Awaitable, Callable
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Any

from fastapi import FastAPI, HTTPException, Request, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse, JSONResponse
from fastapi.staticfiles import StaticFiles
from starlette.datastructures import UploadFile

from explaindrive.language.backends import check_backend
from explaindrive.language.encoders import DEFAULT_ENCODER, check_encoder
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.sim.scenario.files import default_scenario
from explaindrive.web.audio import AudioRejectedError, read_upload
from explaindrive.web.manager import (
    RideConflictError,
    RideManager,
    RideStartError,
    SessionFactory,
)
from explaindrive.web.models import AnswerRequest, SayRequest, StartRequest
from explaindrive.web.scene import load_scene

log = logging.getLogger(__name__)

STATIC_DIR = Path(__file__).parent / "static"
MAX_UPLOAD_BYTES = 5 * 1024 * 1024  # [B] about five minutes of Opus, 50 s of 16-bit WAV
WS_QUEUE_FRAMES = 64  # frames a slow page may lag before it is resynchronised


class RealStack:
    """The default session factory: shipped policies and the chosen language backend.

    The controller and the language models load on the first ride (on the ride
    worker thread) and are reused by the rides that follow.

    Args:
        backend: language backend, ``embedded`` or ``openai``.
        encoder: LLM-1 sentence encoder of the embedded backend (``minilm`` or ``mpnet``).
    """

    def __init__(self, backend: str = "embedded", encoder: str = DEFAULT_ENCODER) -> None:
        self.backend = check_backend(backend)
        self.encoder = check_encoder(encoder)
        self._controller: Any = None
        self._language: Any = None

    def __call__(self, config: RideConfig) -> RideSession:
        """Build a ride session with ``config`` (its backend is replaced by this one's)."""
        from dataclasses import replace

        from explaindrive.agent.controller import MergedController
        from explaindrive.language.config import LanguageConfig
        from explaindrive.language.stack import make_language_stack

        if self._controller is None:
            self._controller = MergedController.from_package()
        if self._language is None:
            language_config = LanguageConfig().with_encoder(self.encoder)
            self._language = make_language_stack(self.backend, language_config).load()
        return RideSession(replace(config, backend=self.backend), self._controller, self._language)


def create_app(
    session_factory: SessionFactory | None = None,
    *,
    backend: str = "embedded",
    encoder: str = DEFAULT_ENCODER,
    step_period_s: float = 1.0,
    max_upload_bytes: int = MAX_UPLOAD_BYTES,
) -> FastAPI:
    """Build the web app.

    Args:
        session_factory: builds a ride session from its settings; the real stack
            (:class:`RealStack` with ``backend``) when omitted. Tests inject fakes here.
        backend: language backend of the default factory.
        encoder: LLM-1 sentence encoder of the default factory's embedded backend.
        step_period_s: wall time per 1 s control step [s]; 1.0 rides in real time.
        max_upload_bytes: largest accepted audio upload [B].
    """
    factory = session_factory or RealStack(backend, encoder)
    scene = load_scene(default_scenario().net_file)
    manager = RideManager(factory, scene, step_period_s=step_period_s)

    @asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        manager.start_worker()
        try:
            yield
        finally:
            await asyncio.to_thread(manager.shutdown)

    app = FastAPI(title="ExplainDrive passenger", lifespan=lifespan)
    app.state.manager = manager
    app.mount("/static", StaticFiles(directory=STATIC_DIR), name="static")

    async def call(name: str, *args: Any) -> Any:
        try:
            return await asyncio.wrap_future(manager.submit(name, *args))
        except RideConflictError as exc:
            raise HTTPException(status_code=409, detail=str(exc)) from exc
        except RideStartError as exc:
            raise HTTPException(status_code=503, detail=str(exc)) from exc

    @app.get("/", include_in_schema=False)
    async def index() -> FileResponse:
        return FileResponse(STATIC_DIR / "index.html", media_type="text/html")

    @app.get("/api/scene")
    async def get_scene() -> dict[str, Any]:
        """The road network the page draws."""
        return scene.to_json()

    @app.get("/api/status")
    async def get_status() -> dict[str, Any]:
        """The ride's state."""
        return manager.status()

    @app.post("/api/ride/start")
    async def start(body: StartRequest) -> dict[str, Any]:
        """Start a new ride (409 while one is running or paused)."""
        result: dict[str, Any] = await call("start", body)
        return result

    def _simple(name: str) -> Callable[[], Awaitable[dict[str, Any]]]:
        async def endpoint() -> dict[str, Any]:
            result: dict[str, Any] = await call(name)
            return result

        endpoint.__name__ = name
        endpoint.__doc__ = f"{name.capitalize()} the ride."
        return endpoint

    for name in ("pause", "resume", "reset"):
        app.post(f"/api/ride/{name}")(_simple(name))

    @app.post("/api/ride/say", status_code=202)
    async def say(body: SayRequest) -> dict[str, Any]:
        """A typed passenger line; it is interpreted while the ride goes on."""
        result: dict[str, Any] = await call("say", body.text)
        return result

    @app.post("/api/ride/audio", status_code=202)
    async def audio(request: Request) -> dict[str, Any]:
        """A recorded passenger line (multipart field ``file``); transcribed by Whisper."""
        if manager.status()["state"] not in ("running", "paused"):
            raise HTTPException(status_code=409, detail="no ride is running; start one")
        length = request.headers.get("content-length")
        if length is not None and length.isdigit() and int(length) > max_upload_bytes + 16_384:
            raise HTTPException(
                status_code=413, detail=f"the upload exceeds {max_upload_bytes} bytes"
            )
        try:
            async with request.form(max_files=1, max_fields=0) as form:
                upload = form.get("file")
                if not isinstance(upload, UploadFile):
                    raise HTTPException(
                        status_code=422, detail="send the recording as multipart field 'file'"
                    )
                data, suffix = await read_upload(upload, max_upload_bytes)
        except AudioRejectedError as exc:
            raise HTTPException(status_code=exc.status_code, detail=str(exc)) from exc
        except HTTPException:
            raise
        except Exception as exc:  # malformed multipart bodies
            raise HTTPException(status_code=400, detail=f"unreadable upload: {exc}") from exc
        path = manager.new_upload_path(suffix)
        path.write_bytes(data)
        try:
            result: dict[str, Any] = await call("audio", path)
        except HTTPException:
            path.unlink(missing_ok=True)
            raise
        return result

    @app.post("/api/ride/answer")
    async def answer(body: AnswerRequest) -> dict[str, Any]:
        """Answer the pending confirmation question (409 when none is pending)."""
        result: dict[str, Any] = await call("answer", body.yes)
        return result

    @app.exception_handler(RuntimeError)
    async def worker_down(_: Request, exc: RuntimeError) -> JSONResponse:
        log.error("request failed: %s", exc)
        return JSONResponse(status_code=503, content={"detail": str(exc)})

    @app.websocket("/ws")
    async def stream(websocket: WebSocket) -> None:
        """A snapshot of the ride, then every frame and status change."""
        await websocket.accept()
        loop = asyncio.get_running_loop()
        inbox: asyncio.Queue[dict[str, Any] | None] = asyncio.Queue(maxsize=WS_QUEUE_FRAMES)

        def deliver(message: dict[str, Any]) -> None:
            if inbox.full():  # the page lags: drop what it missed, send a fresh snapshot
                while not inbox.empty():
                    inbox.get_nowait()
                inbox.put_nowait(None)
            else:
                inbox.put_nowait(message)

        def listener(message: dict[str, Any]) -> None:
            loop.call_soon_threadsafe(deliver, message)

        first = manager.subscribe(listener)

        async def send() -> None:
            await websocket.send_json(first)
            while True:
                message = await inbox.get()
                await websocket.send_json(message if message is not None else manager.snapshot())

        async def receive() -> None:
            while True:
                await websocket.receive_text()  # pages send nothing but keep-alives

        tasks = [asyncio.create_task(send()), asyncio.create_task(receive())]
        try:
            await asyncio.wait(tasks, return_when=asyncio.FIRST_COMPLETED)
        finally:
            manager.unsubscribe(listener)
            for task in tasks:
                task.cancel()
            for task in tasks:
                with contextlib.suppress(asyncio.CancelledError, WebSocketDisconnect, Exception):
                    await task

    return app
