"""``capnav serve MAP``: keep one map loaded behind a web page and JSON endpoints (loopback only
unless ``--host`` says otherwise)."""

from __future__ import annotations

import ipaddress
from pathlib import Path
from typing import Annotated

import typer


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
        map_path: Annotated[Path, typer.Argument(help="a captioned map (capnav map + capnav caption)")],
        host: Annotated[str, typer.Option(help="address to listen on; anything but loopback exposes the map "
                                               "to your network")] = "127.0.0.1",
        port: Annotated[int, typer.Option(min=0, max=65535, help="TCP port (0: any free one)")] = 8765,
        rate: Annotated[float, typer.Option(min=0.0, help="requests per second per client (0: no limit)")] = 50.0,
        burst: Annotated[int, typer.Option(min=1, help="requests a client may send at once")] = 100,
        max_body: Annotated[int, typer.Option(min=256, help="largest request body in bytes")] = 16_384,
        verifier: Annotated[str, typer.Option(help="offline | none | gemini | openai | hf-local")] = "offline",
        embedder: Annotated[str, typer.Option(help="auto (the map's model) or a backend name")] = "auto",
        embedder_path: Annotated[Path | None, typer.Option(help="local model folder for other embedders")] = None,
    ) -> None:
        """Serve a map: a page to ask it in words and see the answer on the map, plus a JSON API."""
        from rich.console import Console

        from capnav.core.errors import InputError

        try:
            import uvicorn

            from capnav.api import CapNav
            from capnav.serve import ServeConfig, create_app
        except ImportError as e:
            raise InputError(f"capnav serve needs the serve extra: pip install 'capnav[serve]' ({e})") from None
        con = Console(stderr=True)
        nav = CapNav.open(map_path, embedder=embedder, embedder_path=embedder_path, verifier=verifier)
        nav.embedder  # noqa: B018 - fail here, with one line, when the map cannot be asked
        app = create_app(nav, ServeConfig(max_body=max_body, rate=rate, burst=burst))
        if not is_loopback(host):
            con.print(f"[yellow]warning:[/] listening on {host}: anyone who can reach it can read the map",
                      highlight=False)
        con.print(f"serving {map_path} ({len(nav.map.objects)} objects) on http://{host}:{port}/", highlight=False)
        uvicorn.run(app, host=host, port=port, log_level="warning")
