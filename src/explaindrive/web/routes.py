"""The web API's route handlers, one module-level function per endpoint.

Handlers find the ride through the app they serve (:func:`ride_manager`, from
``app.state``), so they can be read, tested and mounted on their own:
:data:`read_router` (the page, the scene, the status), :data:`ride_router` (the
ride's commands) and :data:`stream_router` (the WebSocket).
"""

from __future__ import annotations

import asyncio
import contextlib
from dataclasses import dataclass
from typing import Annotated, Any

from fastapi import APIRouter, Depends, HTTPException, Request, WebSocket, WebSocketDisconnect
from fastapi.responses import HTMLResponse
from starlette.datastructures import UploadFile
from starlette.exceptions import HTTPException as StarletteHTTPException

from explaindrive.ride.inputs import SpokenLine, TypedLine
from explaindrive.web.audio import AudioRejectedError, decode_bounded, read_upload, wav_bytes
from explaindrive.web.jobs import (
    Answer,
    Hear,
    Pause,
    Reset,
    Resume,
    RideBusyError,
    RideConflictError,
    RideJob,
    RideStartError,
    Start,
)
from explaindrive.web.manager import RideManager
from explaindrive.web.models import AnswerRequest, SayRequest, StartRequest
from explaindrive.web.page import render_page
from explaindrive.web.scene import Scene

MAX_DETAIL_CHARS = 200  # characters of each message or location part in an error answer
WS_QUEUE_FRAMES = 64  # frames a slow page may lag before it is resynchronised


@dataclass(frozen=True)
class UploadLimits:
    """How large a recording the app accepts.

    Attributes:
        max_upload_bytes: largest accepted audio upload [B].
        max_audio_s: longest accepted recording, counted while it is decoded [s].
    """

    max_upload_bytes: int
    max_audio_s: float


def ride_manager(request: Request) -> RideManager:
    """The ride manager of the app serving ``request``."""
    manager: RideManager = request.app.state.manager
    return manager


Manager = Annotated[RideManager, Depends(ride_manager)]


async def run_job(manager: RideManager, job: RideJob) -> dict[str, Any]:
    """Run ``job`` on the ride worker; its errors become HTTP answers."""
    try:
        result: dict[str, Any] = await asyncio.wrap_future(manager.submit(job))
    except RideConflictError as exc:
        raise HTTPException(status_code=409, detail=str(exc)) from exc
    except RideBusyError as exc:
        raise HTTPException(status_code=429, detail=str(exc)) from exc
    except RideStartError as exc:
        raise HTTPException(status_code=503, detail=str(exc)) from exc
    return result


# ---------------------------------------------------------------------- the page and reads
read_router = APIRouter()


@read_router.get("/", include_in_schema=False)
async def index() -> HTMLResponse:
    """The passenger page."""
    return HTMLResponse(render_page())


@read_router.get("/api/scene")
async def get_scene(request: Request) -> dict[str, Any]:
    """The road network the page draws."""
    scene: Scene = request.app.state.scene
    result: dict[str, Any] = scene.to_json()
    return result


@read_router.get("/api/status")
async def get_status(manager: Manager) -> dict[str, Any]:
    """The ride's state."""
    return manager.status()


# ---------------------------------------------------------------------- the ride's commands
ride_router = APIRouter(prefix="/api/ride")


@ride_router.post("/start")
async def start(body: StartRequest, manager: Manager) -> dict[str, Any]:
    """Start a new ride (409 while one is running or paused)."""
    return await run_job(manager, Start(body))


@ride_router.post("/pause")
async def pause(manager: Manager) -> dict[str, Any]:
    """Pause the ride."""
    return await run_job(manager, Pause())


@ride_router.post("/resume")
async def resume(manager: Manager) -> dict[str, Any]:
    """Resume the ride."""
    return await run_job(manager, Resume())


@ride_router.post("/reset")
async def reset(manager: Manager) -> dict[str, Any]:
    """Reset the ride."""
    return await run_job(manager, Reset())


@ride_router.post("/say", status_code=202)
async def say(body: SayRequest, manager: Manager) -> dict[str, Any]:
    """A typed passenger line; it is interpreted while the ride goes on."""
    return await run_job(manager, Hear(TypedLine(body.text)))


@ride_router.post("/audio", status_code=202)
async def audio(request: Request, manager: Manager) -> dict[str, Any]:
    """A recorded passenger line (multipart field ``file``); transcribed by Whisper."""
    limits: UploadLimits = request.app.state.upload_limits
    if manager.status()["state"] not in ("running", "paused"):
        raise HTTPException(status_code=409, detail="no ride is running; start one")
    data = await _read_recording(request, limits.max_upload_bytes)
    try:
        samples = await asyncio.to_thread(decode_bounded, data, limits.max_audio_s)
    except AudioRejectedError as exc:
        raise HTTPException(status_code=exc.status_code, detail=str(exc)) from exc
    path = manager.new_upload_path(".wav")
    path.write_bytes(wav_bytes(samples))
    try:
        return await run_job(manager, Hear(SpokenLine(path)))
    except HTTPException:
        path.unlink(missing_ok=True)
        raise


@ride_router.post("/answer")
async def answer(body: AnswerRequest, manager: Manager) -> dict[str, Any]:
    """Answer the pending confirmation question (409 when none is pending)."""
    return await run_job(manager, Answer(body.yes))


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


# ---------------------------------------------------------------------- the stream
stream_router = APIRouter()


@stream_router.websocket("/ws")
async def stream(websocket: WebSocket) -> None:
    """A snapshot of the ride, then every frame and status change."""
    manager: RideManager = websocket.app.state.manager
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
