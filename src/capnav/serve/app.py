"""``create_app(maps)``: the map server's Starlette app (``capnav serve`` runs it with uvicorn).

The maps, the embedder and the planner's costmaps load once and stay, so each question costs
milliseconds. The event loop only parses requests and writes answers: asks and plans run on a
bounded pool of workers, each with its own ``CapNav`` per map: processes (``serve.procpool``,
what ``capnav serve`` runs: each has a GIL of its own) or threads (``serve.pool``, for maps
handed over in memory), so ``/healthz``, ``/readyz``, the page and the map picture answer while
asks run. Several maps are
served under their names (``/api/maps/{name}/...``); the unnamed routes (``/api/query``, ...)
serve the first map. Bad input is a 4xx JSON ``{"error": why}``; a full or late pool is a 503
with the reason.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import math
import threading
from collections.abc import AsyncIterator, Callable, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import JSONResponse, Response
from starlette.routing import Route

from capnav.api import CapNav
from capnav.core.errors import CapNavError, InputError, ModelError, NotFoundError
from capnav.mapping.cmap import CapNavMap
from capnav.serve.edges import AccessLog, BearerToken, BodyDeadline
from capnav.serve.jobs import plan_job, process_state, query_job
from capnav.serve.jsonbody import parse_bounded
from capnav.serve.limits import BodyLimit, RateLimit
from capnav.serve.maps import AskOptions, ServedMap, WorkerState, default_robot, map_name, unique_names
from capnav.serve.pool import Busy, Overtime, WorkPool
from capnav.serve.procpool import ProcessPool

__all__ = ["ServeConfig", "create_app", "default_robot"]

log = logging.getLogger("capnav.serve")
_CSP = "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'; object-src 'none'; " \
       "frame-ancestors 'none'"
_STATIC = {"index.html": "text/html; charset=utf-8", "app.js": "text/javascript; charset=utf-8",
           "style.css": "text/css; charset=utf-8"}


#: ``ServeConfig.pool``: worker processes (a GIL each) or worker threads (maps in memory).
POOLS = ("processes", "threads")


@dataclass(frozen=True)
class ServeConfig:
    """Limits of the server. Requests: bodies up to ``max_body`` bytes, JSON nested at most
    ``max_depth`` deep with at most ``max_elements`` values, the whole body within
    ``body_timeout`` s; ``rate`` requests per second per client with bursts of ``burst`` (0 = no
    rate limit); at most ``max_k`` runners-up. Work: ``workers`` threads or processes (``pool``;
    processes need maps given as files), ``queue`` asks waiting
    beyond them (more: 503), each ask answered within ``time_limit`` s (else 503). ``token``: the
    bearer token every ``/api`` request must carry (None: none needed)."""

    max_body: int = 16_384
    rate: float = 50.0
    burst: int = 100
    max_k: int = 20
    warm_up: bool = True  # load the embedder and compile the planner at start-up, not on the first question
    workers: int = 2
    queue: int = 64
    time_limit: float = 10.0
    max_depth: int = 16
    max_elements: int = 2_000
    body_timeout: float = 10.0
    token: str | None = None
    access_log: bool = False
    #: Listen before the maps and the embedder are loaded (``/readyz`` says when they are); False
    #: waits in the start-up hook, as a test client or an embedding application expects.
    load_in_background: bool = False
    pool: str = "threads"

    def __post_init__(self) -> None:
        if self.max_body < 256 or self.rate < 0 or self.burst < 1 or self.max_k < 0:
            raise InputError("ServeConfig: max_body >= 256, rate >= 0, burst >= 1 and max_k >= 0 are required")
        if self.workers < 1 or self.queue < 0 or not self.time_limit > 0 or not self.body_timeout > 0:
            raise InputError("ServeConfig: workers >= 1, queue >= 0, time_limit > 0 and body_timeout > 0 are required")
        if self.max_depth < 2 or self.max_elements < 4:
            raise InputError("ServeConfig: max_depth >= 2 and max_elements >= 4 are required")
        if self.pool not in POOLS:
            raise InputError(f"ServeConfig: pool must be one of {', '.join(POOLS)}, got {self.pool!r}")
        if self.token is not None and len(self.token) < 8:
            raise InputError("the bearer token must be at least 8 characters")


def _error(status: int, why: str, headers: dict[str, str] | None = None) -> JSONResponse:
    return JSONResponse({"error": why}, status_code=status, headers=headers)


def _robot(raw: Any, what: str = "robot") -> tuple[float, float, float] | None:
    if raw is None:
        return None
    if not isinstance(raw, list) or len(raw) not in (2, 3) or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in raw):
        raise InputError(f"{what} must be [x, y] or [x, y, yaw] finite numbers (m, rad), got {raw!r}")
    return (float(raw[0]), float(raw[1]), float(raw[2]) if len(raw) == 3 else 0.0)


MapInput = CapNav | CapNavMap | str | Path


class MapSet:
    """The served maps by name, in the order given; ``reload`` swaps changed files in whole."""

    def __init__(self, maps: list[ServedMap]) -> None:
        self._maps = {m.name: m for m in maps}
        self.first = maps[0].name
        self._lock = threading.Lock()

    def get(self, name: str | None) -> ServedMap:
        m = self._maps.get(self.first if name is None else name)
        if m is None:
            raise NotFoundError(f"no map named {name!r}; this server has {', '.join(self._maps)}")
        return m

    def all(self) -> list[ServedMap]:
        return list(self._maps.values())

    def reload(self) -> dict[str, str]:
        """Open again every map file that changed on disk; a file that fails its checks keeps the
        map it replaces and says why. Returns {name: what happened}."""
        out: dict[str, str] = {}
        with self._lock:
            for m in self.all():
                if m.path is None:
                    out[m.name] = "kept (given in memory, no file to reload)"
                    continue
                try:
                    if not m.changed_on_disk():
                        out[m.name] = f"unchanged (version {m.version})"
                        continue
                    nav = CapNav.open(m.path, embedder=m.options.embedder, embedder_path=m.options.embedder_path,
                                      verifier=m.options.verifier, retrieval=m.nav.retrieval_config,
                                      planner=m.nav.planner_config)
                    new = ServedMap.make(m.name, nav, m.options, m.path, m.version + 1)
                except (CapNavError, OSError) as e:
                    out[m.name] = f"error: {e}; still serving version {m.version}"
                    log.warning("reload of %s failed: %s", m.path, e)
                    continue
                self._maps[m.name] = new
                out[m.name] = f"reloaded (version {new.version}, {len(nav.map.objects)} objects)"
                log.info("reloaded %s as version %d", m.path, new.version)
        return out


def _served(item: MapInput, options: AskOptions | None) -> ServedMap:
    if isinstance(item, CapNav):
        opts = options or AskOptions(getattr(item, "_embedder_spec", "auto"), getattr(item, "_embedder_path", None),
                                     getattr(item, "_verifier_name", "offline"))
        name = map_name(item.source) if item.source is not None else "map"
        return ServedMap.make(name, item, opts, item.source)
    if isinstance(item, CapNavMap):
        opts = options or AskOptions()
        return ServedMap.make("map", CapNav(item), opts)
    return ServedMap.open(Path(item), options or AskOptions())


def create_app(maps: MapInput | Sequence[MapInput], config: ServeConfig | None = None,
               options: AskOptions | None = None) -> Any:
    """The ASGI app over one map or several (``CapNav``s, ``CapNavMap``s or map file paths; the
    first one is the default). Making it opens the map files and nothing else; the workers load
    the embedder and warm up in the start-up hook."""
    cfg = config or ServeConfig()
    items: list[MapInput] = list(maps) if isinstance(maps, list | tuple) else [maps]  # type: ignore[list-item]
    if not items:
        raise InputError("create_app needs at least one map")
    served = [_served(i, options) for i in items]
    names = [m.name for m in served]
    if len(set(names)) != len(names):
        paths = [m.path for m in served]
        if all(p is not None for p in paths):
            unique_names([p for p in paths if p is not None])  # raises naming the two files
        for k, m in enumerate(served):  # in-memory maps: number them
            m.name = f"{m.name}-{k + 1}" if names.count(m.name) > 1 else m.name
    mapset = MapSet(served)
    processes = cfg.pool == "processes"
    pool: WorkPool[WorkerState] | ProcessPool
    if processes:
        if not all(isinstance(i, str | Path) for i in items):
            raise InputError("worker processes open the maps from their files: give map file paths, or serve maps "
                             "in memory with ServeConfig(pool='threads')")
        pool = ProcessPool(cfg.workers, cfg.queue,
                           functools.partial(process_state, [m.ref() for m in served], cfg.warm_up))
    else:
        def make_state(i: int) -> WorkerState:
            st = WorkerState()
            if cfg.warm_up:
                for m in mapset.all():
                    st.warm(m)
            return st

        workers = 1 if any(m.options.shared_instance for m in served) else cfg.workers
        pool = WorkPool(workers, cfg.queue, make_state)

    def job_map(m: ServedMap) -> Any:
        return m.ref() if processes else m
    reload_lock = asyncio.Lock()

    async def reload_maps() -> dict[str, str]:
        async with reload_lock:
            result = await asyncio.to_thread(mapset.reload)
        for m in mapset.all():  # draw changed pictures now, not in the next page's request
            await asyncio.to_thread(m.picture)
        return result

    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        pool.start()
        pictures = asyncio.ensure_future(asyncio.gather(*(asyncio.to_thread(m.picture) for m in mapset.all())))
        if not cfg.load_in_background:
            await asyncio.to_thread(pool.wait_ready)
            with contextlib.suppress(CapNavError):
                await pictures
        try:
            yield
        finally:
            await asyncio.to_thread(pool.close)  # uvicorn has drained the requests; let the workers end

    def chosen_map(request: Request) -> ServedMap:
        return mapset.get(request.path_params.get("name"))

    async def index(request: Request) -> Response:
        return _static("index.html")

    async def static(request: Request) -> Response:
        return _static(request.path_params["name"])

    async def healthz(request: Request) -> Response:
        return JSONResponse({"ok": True, "objects": len(mapset.get(None).nav.map.objects)})

    async def readyz(request: Request) -> Response:
        body: dict[str, Any] = {"ready": pool.ready, "workers": pool.workers, "in_flight": pool.in_flight,
                                "maps": [m.describe() for m in mapset.all()]}
        if pool.load_error is not None:
            body["why"] = f"a worker failed to load: {pool.load_error}"
        elif not pool.ready:
            body["why"] = "loading the maps and the embedder"
        return JSONResponse(body, status_code=200 if pool.ready else 503)

    async def maps_list(request: Request) -> Response:
        return JSONResponse({"default": mapset.first, "maps": [m.describe() for m in mapset.all()]})

    async def reload_route(request: Request) -> Response:
        result = await reload_maps()
        failed = any(v.startswith("error") for v in result.values())
        return JSONResponse({"maps": result}, status_code=422 if failed else 200)

    async def map_info(request: Request) -> Response:
        m = chosen_map(request)
        pic = await asyncio.to_thread(m.picture)
        nav = m.nav
        return JSONResponse({"name": m.name, "version": m.version, "grid": nav.map.occupancy.spec.to_dict(),
                             "picture": pic.to_dict(), "objects": len(nav.map.objects),
                             "default_robot": None if m.robot0 is None else list(m.robot0),
                             "source": None if m.path is None else m.path.name,
                             "captioned": all(o.caption for o in nav.map.objects)})

    async def map_png(request: Request) -> Response:
        m = chosen_map(request)
        pic = await asyncio.to_thread(m.picture)
        return Response(pic.png, media_type="image/png", headers={"cache-control": "no-cache"})

    async def objects(request: Request) -> Response:
        return JSONResponse({"objects": [o.to_dict() for o in chosen_map(request).nav.objects()]})

    async def view_png(request: Request) -> Response:
        m = chosen_map(request)
        try:
            oid = int(request.path_params["oid"])
            png = m.nav.view_png(oid)
        except (ValueError, NotFoundError) as e:
            return _error(404, str(e))
        if png is None:
            return _error(404, f"object {oid} has no captioning view")
        return Response(png, media_type="image/png")

    async def work(request: Request, job: Callable[[WorkerState, float], bytes]) -> Response:
        if not pool.ready:
            why = f"a worker failed to load: {pool.load_error}" if pool.load_error is not None else \
                "still loading the maps and the embedder (see /readyz)"
            return _error(503, why, {"retry-after": "2"})
        try:
            out = await pool.run(job, cfg.time_limit)
        except Busy as e:
            return _error(503, str(e), {"retry-after": "1"})
        except Overtime as e:
            return _error(503, str(e))
        except NotFoundError as e:
            return _error(404, str(e))
        except InputError as e:
            return _error(422, str(e))
        except ModelError as e:
            return _error(503, f"a model backend failed: {e}")
        return Response(out, media_type="application/json")

    async def query(request: Request) -> Response:
        m = chosen_map(request)
        body = await _json_body(request, cfg)
        text = body.get("text")
        if not isinstance(text, str):
            return _error(422, "'text' (the instruction, a string) is required")
        k = body.get("k", 5)
        if not isinstance(k, int) or isinstance(k, bool) or not 0 <= k <= cfg.max_k:
            return _error(422, f"'k' must be an integer from 0 to {cfg.max_k}, got {k!r}")
        try:
            robot = _robot(body.get("robot"))
        except InputError as e:
            return _error(422, str(e))
        return await work(request, functools.partial(query_job, job_map(m), text, k, robot))

    async def plan_route(request: Request) -> Response:
        m = chosen_map(request)
        body = await _json_body(request, cfg)
        oid = body.get("object")
        if not isinstance(oid, int) or isinstance(oid, bool):
            return _error(422, "'object' (a map object id, an integer) is required")
        try:
            start = _robot(body.get("start"), "start")  # None: the map's last camera pose
        except InputError as e:
            return _error(422, str(e))
        return await work(request, functools.partial(plan_job, job_map(m), oid, start))

    async def http_error(request: Request, exc: Exception) -> Response:
        assert isinstance(exc, HTTPException)
        return _error(exc.status_code, str(exc.detail))

    async def not_found(request: Request, exc: Exception) -> Response:
        return _error(404, str(exc))

    per_map = [
        ("/map", map_info, ["GET"]), ("/map.png", map_png, ["GET"]), ("/objects", objects, ["GET"]),
        ("/objects/{oid}/view.png", view_png, ["GET"]), ("/query", query, ["POST"]), ("/plan", plan_route, ["POST"]),
    ]
    routes = [
        Route("/", index), Route("/static/{name}", static), Route("/healthz", healthz), Route("/readyz", readyz),
        Route("/api/maps", maps_list), Route("/api/reload", reload_route, methods=["POST"]),
        *(Route(f"/api{p}", h, methods=ms) for p, h, ms in per_map),
        *(Route(f"/api/maps/{{name}}{p}", h, methods=ms) for p, h, ms in per_map),
    ]
    app = Starlette(routes=routes, lifespan=lifespan,
                    exception_handlers={HTTPException: http_error, NotFoundError: not_found})
    app.state.maps = mapset
    app.state.pool = pool
    app.state.reload = reload_maps
    app.add_middleware(SecurityHeaders)
    app.add_middleware(BodyLimit, max_body=cfg.max_body)
    app.add_middleware(BodyDeadline, timeout=cfg.body_timeout)
    if cfg.token is not None:
        app.add_middleware(BearerToken, token=cfg.token)
    app.add_middleware(RateLimit, rate=cfg.rate, burst=cfg.burst)
    if cfg.access_log:
        app.add_middleware(AccessLog)
    return app


async def _json_body(request: Request, cfg: ServeConfig) -> dict[str, Any]:
    if "application/json" not in request.headers.get("content-type", ""):
        raise HTTPException(415, "send JSON with Content-Type: application/json")
    raw = await request.body()
    try:
        body = parse_bounded(raw, cfg.max_depth, cfg.max_elements)
    except InputError as e:
        raise HTTPException(400, str(e)) from None
    if not isinstance(body, dict):
        raise HTTPException(422, f"the body must be a JSON object, got {type(body).__name__}")
    return body


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
