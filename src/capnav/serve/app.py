"""``create_app(map)``: the map server's Starlette app (``capnav serve`` runs it with uvicorn).

One ``CapNav`` is kept for the server's life, so the map, the embedder and the planner's costmap
load once and each question costs milliseconds. Handlers run on the event loop one at a time
(the stage objects are not shared across threads). Bad input is a 4xx JSON ``{"error": why}``.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import time
from collections.abc import AsyncIterator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage
from starlette.applications import Starlette
from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from capnav.api import CapNav
from capnav.core.errors import CapNavError, InputError, NotFoundError
from capnav.core.grid import FREE
from capnav.mapping.cmap import CapNavMap
from capnav.serve.limits import BodyLimit, RateLimit
from capnav.viz.mapimage import MapPicture, map_picture

_CSP = "default-src 'self'; img-src 'self' data:; style-src 'self'; script-src 'self'; object-src 'none'; " \
       "frame-ancestors 'none'"
_STATIC = {"index.html": "text/html; charset=utf-8", "app.js": "text/javascript; charset=utf-8",
           "style.css": "text/css; charset=utf-8"}


@dataclass(frozen=True)
class ServeConfig:
    """Limits of the server: request bodies up to ``max_body`` bytes, ``rate`` requests per second
    per client with bursts of ``burst`` (0 = no rate limit), at most ``max_k`` runners-up."""

    max_body: int = 16_384
    rate: float = 50.0
    burst: int = 100
    max_k: int = 20
    warm_up: bool = True  # load the embedder and compile the planner at start-up, not on the first question

    def __post_init__(self) -> None:
        if self.max_body < 256 or self.rate < 0 or self.burst < 1 or self.max_k < 0:
            raise InputError("ServeConfig: max_body >= 256, rate >= 0, burst >= 1 and max_k >= 0 are required")


def _error(status: int, why: str) -> JSONResponse:
    return JSONResponse({"error": why}, status_code=status)


def default_robot(nav: CapNav) -> tuple[float, float] | None:
    """A start for the page until the user clicks one: the map's last camera pose, as ``capnav
    navigate`` starts (``CapNav.start_pose``); for a map with no camera path, the free cell farthest
    from any non-free cell (an open spot in the middle of a room)."""
    if nav.map.trajectory is not None and len(nav.map.trajectory):
        (x, y, _), _ = nav.start_pose()
        return (round(x, 3), round(y, 3))
    occ = nav.occupancy
    free = occ.cells == FREE
    if not free.any():
        return None
    dist = ndimage.distance_transform_edt(free)
    r, c = np.unravel_index(int(np.argmax(dist)), dist.shape)
    x, y = occ.spec.to_world(np.array([r, c]))
    return (round(float(x), 3), round(float(y), 3))


def _robot(body: dict[str, Any]) -> tuple[float, float, float] | None:
    raw = body.get("robot")
    if raw is None:
        return None
    if not isinstance(raw, list) or len(raw) not in (2, 3) or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in raw):
        raise InputError(f"robot must be [x, y] or [x, y, yaw] finite numbers (m, rad), got {raw!r}")
    return (float(raw[0]), float(raw[1]), float(raw[2]) if len(raw) == 3 else 0.0)


async def _json_body(request: Request) -> dict[str, Any]:
    if "application/json" not in request.headers.get("content-type", ""):
        raise HTTPException(415, "send JSON with Content-Type: application/json")
    try:
        body = await request.json()
    except ValueError as e:
        raise HTTPException(400, f"the body is not valid JSON ({e})") from None
    if not isinstance(body, dict):
        raise HTTPException(422, f"the body must be a JSON object, got {type(body).__name__}")
    return body


def create_app(map_or_nav: CapNav | CapNavMap | str | Path, config: ServeConfig | None = None) -> Any:
    """The ASGI app over one map (a ``CapNav``, a ``CapNavMap`` or a map file path). Making it loads
    the map file when given a path and nothing else; models load in the start-up hook (or on the
    first question when ``warm_up`` is off)."""
    cfg = config or ServeConfig()
    if isinstance(map_or_nav, CapNav):
        nav = map_or_nav
    elif isinstance(map_or_nav, CapNavMap):
        nav = CapNav(map_or_nav)
    else:
        nav = CapNav.open(map_or_nav)
    lock = asyncio.Lock()
    picture: list[MapPicture] = []

    def pic() -> MapPicture:
        if not picture:
            picture.append(map_picture(nav.map))
        return picture[0]

    robot0 = default_robot(nav)

    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        if cfg.warm_up and nav.map.objects:
            with contextlib.suppress(CapNavError):  # an uncaptioned map still serves its picture
                o = nav.map.objects[0]
                nav.ask(o.label, robot=robot0)
                if robot0 is not None:
                    nav.plan(robot0, o.id)
            pic()
        yield

    async def index(request: Request) -> Response:
        return _static("index.html")

    async def static(request: Request) -> Response:
        return _static(request.path_params["name"])

    async def healthz(request: Request) -> Response:
        return JSONResponse({"ok": True, "objects": len(nav.map.objects)})

    async def map_info(request: Request) -> Response:
        spec = nav.map.occupancy.spec
        return JSONResponse({"grid": spec.to_dict(), "picture": pic().to_dict(), "objects": len(nav.map.objects),
                             "default_robot": None if robot0 is None else list(robot0),
                             "source": None if nav.source is None else nav.source.name,
                             "captioned": all(o.caption for o in nav.map.objects)})

    async def map_png(request: Request) -> Response:
        return Response(pic().png, media_type="image/png", headers={"cache-control": "no-cache"})

    async def objects(request: Request) -> Response:
        return JSONResponse({"objects": [o.to_dict() for o in nav.objects()]})

    async def view_png(request: Request) -> Response:
        try:
            oid = int(request.path_params["oid"])
            png = nav.view_png(oid)
        except (ValueError, NotFoundError) as e:
            return _error(404, str(e))
        if png is None:
            return _error(404, f"object {oid} has no captioning view")
        return Response(png, media_type="image/png")

    async def query(request: Request) -> Response:
        body = await _json_body(request)
        text = body.get("text")
        if not isinstance(text, str):
            return _error(422, "'text' (the instruction, a string) is required")
        k = body.get("k", 5)
        if not isinstance(k, int) or isinstance(k, bool) or not 0 <= k <= cfg.max_k:
            return _error(422, f"'k' must be an integer from 0 to {cfg.max_k}, got {k!r}")
        try:
            robot = _robot(body)
            async with lock:
                t0, c0 = time.perf_counter(), time.thread_time()
                ans = nav.ask(text, robot=robot, k=k)
                # no goal pose (robot in a wall, nothing found): the answer stands, goal_note says why
                plan = nav.plan(robot, ans) if robot is not None and ans.goal is not None else None
                t1, c1 = time.perf_counter(), time.thread_time()
        except InputError as e:
            return _error(422, str(e))
        out = ans.to_dict()
        out["plan"] = None if plan is None else plan.to_dict()
        out["server_ms"] = {"wall": round((t1 - t0) * 1e3, 3), "cpu": round((c1 - c0) * 1e3, 3)}
        return JSONResponse(out)

    async def plan_route(request: Request) -> Response:
        body = await _json_body(request)
        oid = body.get("object")
        if not isinstance(oid, int) or isinstance(oid, bool):
            return _error(422, "'object' (a map object id, an integer) is required")
        try:
            start = _robot({"robot": body.get("start")})  # None: the map's last camera pose
            async with lock:
                plan = nav.plan(start, oid)
        except NotFoundError as e:
            return _error(404, str(e))
        except InputError as e:
            return _error(422, str(e))
        return JSONResponse(plan.to_dict())

    async def http_error(request: Request, exc: Exception) -> Response:
        assert isinstance(exc, HTTPException)
        return _error(exc.status_code, str(exc.detail))

    routes = [
        Route("/", index), Route("/static/{name}", static), Route("/healthz", healthz),
        Route("/api/map", map_info), Route("/api/map.png", map_png), Route("/api/objects", objects),
        Route("/api/objects/{oid}/view.png", view_png), Route("/api/query", query, methods=["POST"]),
        Route("/api/plan", plan_route, methods=["POST"]),
    ]
    app = Starlette(routes=routes, lifespan=lifespan, exception_handlers={HTTPException: http_error})
    app.state.nav = nav
    app.add_middleware(SecurityHeaders)
    app.add_middleware(BodyLimit, max_body=cfg.max_body)
    app.add_middleware(RateLimit, rate=cfg.rate, burst=cfg.burst)
    return app


def _static(name: str) -> Response:
    if name not in _STATIC:
        return _error(404, f"no page file {name!r}")
    data = resources.files("capnav.serve").joinpath("static", name).read_bytes()
    return Response(data, media_type=_STATIC[name])


class SecurityHeaders:
    """No third-party anything: the page's scripts, styles and images come from this server only."""

    def __init__(self, app: Any) -> None:
        self.app = app

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        async def add(m: Any) -> None:
            if m["type"] == "http.response.start":
                m.setdefault("headers", [])
                m["headers"] = [*m["headers"], (b"content-security-policy", _CSP.encode()),
                                (b"x-content-type-options", b"nosniff"), (b"referrer-policy", b"no-referrer")]
            await send(m)

        await self.app(scope, receive, add if scope["type"] == "http" else send)
