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

Every request passes :class:`~explaindrive.web.guard.RequestGuard` first (``Host``,
``Origin`` and body-size checks). There are no interactive API docs (``/docs``): the
page works offline and Swagger would come from a CDN; ``/openapi.json`` describes the API.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import AsyncIterator, Awaitable, Callable, Iterable
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Any

from fastapi import FastAPI, HTTPException, Request, WebSocket, WebSocketDisconnect
from fastapi.exceptions import RequestValidationError
from fastapi.responses import HTMLResponse, JSONResponse
from fastapi.staticfiles import StaticFiles
from starlette.datastructures import UploadFile
from starlette.exceptions import HTTPException as StarletteHTTPException

from explaindrive.language.backends import check_backend
from explaindrive.language.config import LanguageConfig
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.sim.scenario.files import default_scenario
from explaindrive.web.audio import (
    MAX_AUDIO_S,
    AudioRejectedError,
    decode_bounded,
    read_upload,
    wav_bytes,
)
from explaindrive.web.guard import LOOPBACK_HOSTS, RequestGuard
from explaindrive.web.manager import (
    RideBusyError,
    RideConflictError,
    RideManager,
    RideStartError,
    SessionFactory,
)
from explaindrive.web.models import AnswerRequest, SayRequest, StartRequest
from explaindrive.web.page import STATIC_DIR, render_page
from explaindrive.web.scene import load_scene

log = logging.getLogger(__name__)

MAX_UPLOAD_BYTES = 5 * 1024 * 1024  # [B] about five minutes of Opus, 50 s of 16-bit WAV
MAX_JSON_BYTES = 16 * 1024  # [B] request bodies other than uploads (a request is 300 chars)
MULTIPART_OVERHEAD_BYTES = 16 * 1024  # [B] boundaries and part headers around an upload
MAX_DETAIL_ERRORS = 10  # validation errors listed in a 422 answer
MAX_DETAIL_CHARS = 200  # characters of each message or location part in an error answer
WS_QUEUE_FRAMES = 64  # frames a slow page may lag before it is resynchronised


class RealStack:
    """The default session factory: the shipped policies (or others in their place) and the
    chosen language backend.

    The controller and the language models load on the first ride (on the ride
    worker thread) and are reused by the rides that follow.

    Args:
        backend: language backend, ``embedded`` or ``openai``.
        fast_policy: a fast network in place of the shipped one (a policy ``.pt`` file or
            a training run directory).
        comfort_policy: likewise for the comfort network.
        scenario: ride config fields choosing where the rides drive (the paper's road by
            default; see :class:`~explaindrive.sim.scenario.choice.ScenarioFields`).
        language: the language layer's configuration (endpoint, model...); ``None`` =
            the defaults.
    """

    def __init__(
        self,
        backend: str = "embedded",
        fast_policy: Path | None = None,
        comfort_policy: Path | None = None,
        scenario: dict[str, Any] | None = None,
        language: LanguageConfig | None = None,
    ) -> None:
        self.backend = check_backend(backend)
        self.policies = (fast_policy, comfort_policy)
        self.scenario = dict(scenario or {})
        self.language_config = language or LanguageConfig()
        self._controller: Any = None
        self._language: Any = None

    def __call__(self, config: RideConfig) -> RideSession:
        """Build a ride session with ``config`` (its backend is replaced by this one's)."""
        from explaindrive.agent.controller import MergedController
        from explaindrive.language.stack import make_language_stack

        fast, comfort = self.policies
        if self._controller is None:
            self._controller = MergedController.from_package(fast=fast, comfort=comfort)
        if self._language is None:
            self._language = make_language_stack(self.backend, self.language_config).load()
        config = config.replace(backend=self.backend, fast_policy=fast, comfort_policy=comfort,
                                **self.scenario)  # fmt: skip
        return RideSession(config, self._controller, self._language)


def create_app(
    session_factory: SessionFactory | None = None,
    *,
    backend: str = "embedded",
    step_period_s: float = 1.0,
    max_upload_bytes: int = MAX_UPLOAD_BYTES,
    max_audio_s: float = MAX_AUDIO_S,
    hosts: Iterable[str] = LOOPBACK_HOSTS,
    net_file: Path | None = None,
) -> FastAPI:
    """Build the web app.

    Args:
        session_factory: builds a ride session from its settings; the real stack
            (:class:`RealStack` with ``backend``) when omitted. Tests inject fakes here.
        backend: language backend of the default factory.
        step_period_s: wall time per 1 s control step [s]; 1.0 rides in real time.
        max_upload_bytes: largest accepted audio upload [B].
        max_audio_s: longest accepted recording, counted while it is decoded [s].
        hosts: the host names the server answers to (``Host`` header); the loopback
            names by default (see :func:`explaindrive.web.guard.served_hosts`).
        net_file: the network the rides drive, which the page draws (default: the paper's).
    """
    factory = session_factory or RealStack(backend)
    scene = load_scene(net_file or default_scenario().net_file)
    manager = RideManager(factory, scene, step_period_s=step_period_s)

    @asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        manager.start_worker()
        try:
            yield
        finally:
            await asyncio.to_thread(manager.shutdown)

    app = FastAPI(title="ExplainDrive passenger", lifespan=lifespan, docs_url=None, redoc_url=None)
    app.state.manager = manager
    app.mount("/static", StaticFiles(directory=STATIC_DIR), name="static")
    upload_limit = max_upload_bytes + MULTIPART_OVERHEAD_BYTES
    app.add_middleware(
        RequestGuard,
        hosts=hosts,
        body_limit=lambda path: upload_limit if path == "/api/ride/audio" else MAX_JSON_BYTES,
    )
    _add_error_handlers(app)
    _add_read_routes(app, manager, scene)
    _add_ride_routes(app, manager, max_upload_bytes, max_audio_s)
    _add_stream_route(app, manager)
    return app


def _caller(manager: RideManager) -> Callable[..., Awaitable[Any]]:
    """``call(name, *args)``: run a manager command; its errors become HTTP answers."""

    async def call(name: str, *args: Any) -> Any:
        try:
            return await asyncio.wrap_future(manager.submit(name, *args))
        except RideConflictError as exc:
            raise HTTPException(status_code=409, detail=str(exc)) from exc
        except RideBusyError as exc:
            raise HTTPException(status_code=429, detail=str(exc)) from exc
        except RideStartError as exc:
            raise HTTPException(status_code=503, detail=str(exc)) from exc

    return call


def _add_error_handlers(app: FastAPI) -> None:
    """Short error answers: a 422 never echoes the input, a stopped worker is a 503."""

    @app.exception_handler(RequestValidationError)
    async def invalid(_: Request, exc: RequestValidationError) -> JSONResponse:
        return JSONResponse(status_code=422, content={"detail": short_errors(exc.errors())})

    @app.exception_handler(RuntimeError)
    async def worker_down(_: Request, exc: RuntimeError) -> JSONResponse:
        log.error("request failed: %s", exc)
        return JSONResponse(status_code=503, content={"detail": str(exc)[:MAX_DETAIL_CHARS]})


def short_errors(errors: Iterable[Any]) -> list[dict[str, Any]]:
    """Validation errors as ``{loc, msg, type}``, without the offending input, cut short."""
    out = []
    for error in list(errors)[:MAX_DETAIL_ERRORS]:
        loc = [
            part if isinstance(part, int) else str(part)[:MAX_DETAIL_CHARS]
            for part in error.get("loc", ())
        ]
        out.append(
            {
                "loc": loc[:8],
                "msg": str(error.get("msg", ""))[:MAX_DETAIL_CHARS],
                "type": str(error.get("type", ""))[:MAX_DETAIL_CHARS],
            }
        )
    return out


def _add_read_routes(app: FastAPI, manager: RideManager, scene: Any) -> None:
    """The page, the scene and the status."""

    @app.get("/", include_in_schema=False)
    async def index() -> HTMLResponse:
        return HTMLResponse(render_page())

    @app.get("/api/scene")
    async def get_scene() -> dict[str, Any]:
        """The road network the page draws."""
        result: dict[str, Any] = scene.to_json()
        return result

    @app.get("/api/status")
    async def get_status() -> dict[str, Any]:
        """The ride's state."""
        return manager.status()


def _add_ride_routes(
    app: FastAPI, manager: RideManager, max_upload_bytes: int, max_audio_s: float
) -> None:
    """Start, pause, resume, reset, say, audio and answer."""
    call = _caller(manager)

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
        data = await _read_recording(request, max_upload_bytes)
        try:
            samples = await asyncio.to_thread(decode_bounded, data, max_audio_s)
        except AudioRejectedError as exc:
            raise HTTPException(status_code=exc.status_code, detail=str(exc)) from exc
        path = manager.new_upload_path(".wav")
        path.write_bytes(wav_bytes(samples))
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


async def _read_recording(request: Request, max_upload_bytes: int) -> bytes:
    """The bytes of the multipart field ``file``, checked for type, size and signature."""
    try:
        async with request.form(max_files=1, max_fields=0) as form:
            upload = form.get("file")
            if not isinstance(upload, UploadFile):
                raise HTTPException(
                    status_code=422, detail="send the recording as multipart field 'file'"
                )
            data, _ = await read_upload(upload, max_upload_bytes)
            return data
    except AudioRejectedError as exc:
        raise HTTPException(status_code=exc.status_code, detail=str(exc)) from exc
    except StarletteHTTPException as exc:
        if exc.status_code in (413, 422):  # from the guard while streaming, or no 'file'
            raise
        detail = f"unreadable upload: {exc.detail}"[:MAX_DETAIL_CHARS]
        raise HTTPException(status_code=400, detail=detail) from exc
    except Exception as exc:  # malformed multipart bodies
        detail = f"unreadable upload: {exc}"[:MAX_DETAIL_CHARS]
        raise HTTPException(status_code=400, detail=detail) from exc


def _add_stream_route(app: FastAPI, manager: RideManager) -> None:
    """``/ws``: a snapshot of the ride, then every frame and status change."""

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
