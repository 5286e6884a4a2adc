"""The passenger web app: a FastAPI back end, a WebSocket stream and a static page.

Endpoints (all JSON unless noted):

Route handlers live in :mod:`explaindrive.web.routes`.

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
import logging
from collections.abc import AsyncIterator, Iterable
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from fastapi.staticfiles import StaticFiles

from explaindrive.language.backends import check_backend
from explaindrive.language.config import LanguageConfig
from explaindrive.ride.config import RideConfig
from explaindrive.ride.session import RideSession
from explaindrive.sim.scenario.files import default_scenario
from explaindrive.web.audio import MAX_AUDIO_S
from explaindrive.web.guard import LOOPBACK_HOSTS, RequestGuard
from explaindrive.web.manager import RideManager, SessionFactory
from explaindrive.web.page import STATIC_DIR
from explaindrive.web.routes import (
    MAX_DETAIL_CHARS,
    UploadLimits,
    read_router,
    ride_router,
    stream_router,
)
from explaindrive.web.scene import load_scene

log = logging.getLogger(__name__)

MAX_UPLOAD_BYTES = 5 * 1024 * 1024  # [B] about five minutes of Opus, 50 s of 16-bit WAV
MAX_JSON_BYTES = 16 * 1024  # [B] request bodies other than uploads (a request is 300 chars)
MULTIPART_OVERHEAD_BYTES = 16 * 1024  # [B] boundaries and part headers around an upload
MAX_DETAIL_ERRORS = 10  # validation errors listed in a 422 answer


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
    app.state.scene = scene
    app.state.upload_limits = UploadLimits(max_upload_bytes, max_audio_s)
    _add_error_handlers(app)
    app.include_router(read_router)
    app.include_router(ride_router)
    app.include_router(stream_router)
    return app


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
