"""``capnav serve MAP [MAP ...]``: keep maps loaded behind a web page and JSON endpoints (loopback
only unless ``--host`` says otherwise, and then only with a bearer token)."""

from __future__ import annotations

import ipaddress
import os
import sys
from pathlib import Path
from typing import Annotated

import typer

from capnav.cli.options import finite_float

TOKEN_ENV = "CAPNAV_SERVE_TOKEN"


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def register(app: typer.Typer) -> None:
    @app.command("serve")
    def serve_cmd(
        map_paths: Annotated[list[Path], typer.Argument(
            help="captioned maps (capnav map + capnav caption); each is served under its file name, the first "
                 "also on the unnamed routes")],
        host: Annotated[str, typer.Option(help="address to listen on; anything but loopback exposes the maps "
                                               "to your network and needs --token")] = "127.0.0.1",
        port: Annotated[int, typer.Option(min=0, max=65535, help="TCP port (0: any free one)")] = 8765,
        token: Annotated[str | None, typer.Option(
            help=f"bearer token every /api request must carry (default: ${TOKEN_ENV}); required off loopback")
                         ] = None,
        workers: Annotated[int, typer.Option(min=1, max=64, help="workers that answer asks (one per core)")] = 2,
        pool: Annotated[str, typer.Option(help="processes (a GIL each: asks run side by side and /healthz never "
                                               "waits behind them) or threads (less memory)")] = "processes",
        queue: Annotated[int, typer.Option(min=0, help="asks that may wait for a worker (more: 503)")] = 64,
        time_limit: Annotated[float, typer.Option(parser=finite_float(0.01),
                                                  help="seconds an ask may take (else 503)")] = 10.0,
        body_timeout: Annotated[float, typer.Option(parser=finite_float(0.01),
                                                    help="seconds to receive a request body")] = 10.0,
        header_timeout: Annotated[float, typer.Option(parser=finite_float(0.01),
                                                      help="seconds to receive request headers")] = 10.0,
        rate: Annotated[float, typer.Option(parser=finite_float(0.0),
                                            help="requests per second per client (0: no limit)")] = 50.0,
        burst: Annotated[int, typer.Option(min=1, help="requests a client may send at once")] = 100,
        max_body: Annotated[int, typer.Option(min=256, help="largest request body in bytes")] = 16_384,
        access_log: Annotated[bool, typer.Option("--access-log", help="one log line per request (method, path, "
                                                                      "status, ms)")] = False,
        verifier: Annotated[str, typer.Option(help="offline | none | gemini | openai | hf-local")] = "offline",
        embedder: Annotated[str, typer.Option(help="auto (the map's model) or a backend name")] = "auto",
        embedder_path: Annotated[Path | None, typer.Option(help="local model folder for other embedders")] = None,
        fields: Annotated[bool, typer.Option(help="make each object's goal and walk fields once a worker is up "
                                                  "(about 1 MB an object per worker): asks from new robot positions "
                                                  "are then lookups, with the same answers")] = True,
    ) -> None:
        """Serve maps: a page to ask them in words and see the answer on the map, plus a JSON API.
        SIGHUP or POST /api/reload re-reads map files replaced on disk; SIGTERM finishes the asks
        in progress and stops."""
        import logging
        import threading

        from capnav.core.console import make_console
        from capnav.core.errors import InputError

        try:
            import uvicorn

            from capnav.serve import ServeConfig, create_app
            from capnav.serve.maps import AskOptions, unique_names
            from capnav.serve.protocol import Server, header_protocol
        except ImportError as e:
            raise InputError(f"capnav serve needs the serve extra: {sys.executable} -m pip install "
                             f"'capnav[serve]' ({e})") from None
        con = make_console(stderr=True)
        token = token or os.environ.get(TOKEN_ENV) or None
        if not is_loopback(host) and token is None:
            raise InputError(f"--host {host} is not loopback: anyone who can reach it could read the maps; pass "
                             f"--token TOKEN (or set {TOKEN_ENV}) so that every /api request needs it")
        unique_names(map_paths)
        for p in map_paths:
            if not p.is_file():
                raise InputError(f"map file not found: {p}" + (" (a folder: give the .capnav file in it)"
                                                                if p.is_dir() else ""))
        cfg = ServeConfig(max_body=max_body, rate=rate, burst=burst, workers=workers, queue=queue,
                          time_limit=time_limit, body_timeout=body_timeout, token=token, access_log=access_log,
                          load_in_background=True, pool=pool)
        opts = AskOptions(embedder, embedder_path, verifier, fields)
        app = create_app(list(map_paths), cfg, opts)
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("%(asctime)s %(message)s", "%H:%M:%S"))
        for name in ("capnav.serve", "capnav.serve.access"):
            lg = logging.getLogger(name)
            lg.setLevel(logging.INFO)
            lg.addHandler(handler)
            lg.propagate = False
        if not is_loopback(host):
            con.print(f"[yellow]warning:[/] listening on {host}: the /api routes need the bearer token",
                      highlight=False)
        maps = app.state.maps.all()
        what = ", ".join(f"{m.name} ({len(m.nav.map.objects)} objects)" for m in maps)

        def listening(url: str) -> None:
            con.print(f"serving {what} on {url}", highlight=False)

            def ready() -> None:
                try:
                    app.state.pool.wait_ready()
                except Exception as e:
                    con.print(f"[red]error:[/] a worker failed to load: {e}", highlight=False)
                    return
                con.print(f"ready: {len(maps)} map(s), {app.state.pool.workers} worker {pool}", highlight=False)

            threading.Thread(target=ready, daemon=True).start()

        async def on_hup() -> None:
            result = await app.state.reload()
            con.print("SIGHUP: " + "; ".join(f"{k}: {v}" for k, v in result.items()), highlight=False)

        if pool == "threads":
            # The event loop shares the GIL with the worker threads: hand it over every 1 ms instead of
            # Python's 5 ms, so /healthz and the page wait less behind asks that hold it.
            sys.setswitchinterval(0.001)
        config = uvicorn.Config(app, host=host, port=port, log_level="warning", access_log=False,
                                http=header_protocol(header_timeout), timeout_keep_alive=5,
                                timeout_graceful_shutdown=int(max(1.0, time_limit + 5)), lifespan="on")
        Server(config, listening, on_hup).run()
