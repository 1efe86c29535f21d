"""A real uvicorn (the one ``capnav serve`` runs, with its header deadline) on a free loopback
port, in a thread of the test process, so tests can reach the app's pool and read its logs."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Iterator
from typing import Any

import uvicorn

from capnav.serve.protocol import Server, header_protocol


@contextlib.contextmanager
def live(app: Any, header_timeout: float = 10.0, timeout: float = 120.0) -> Iterator[tuple[str, Server]]:
    urls: list[str] = []
    config = uvicorn.Config(app, host="127.0.0.1", port=0, log_level="warning", access_log=False,
                            http=header_protocol(header_timeout), timeout_keep_alive=5, lifespan="on")
    server = Server(config, urls.append)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + timeout
    while not urls:
        if not thread.is_alive() or time.monotonic() > deadline:
            raise RuntimeError("the server did not start listening")
        time.sleep(0.05)
    try:
        yield urls[0].rstrip("/"), server
    finally:
        server.should_exit = True
        thread.join(30)


def raw(url: str, data: bytes, wait: float = 15.0, then_close: bool = False) -> tuple[bytes, float]:
    """Send ``data`` on a new connection and read until the server closes it (or ``wait`` s pass);
    returns what came back and the seconds it took."""
    host, port = url.removeprefix("http://").split(":")
    t0 = time.monotonic()
    with socket.create_connection((host, int(port)), timeout=wait) as s:
        s.sendall(data)
        if then_close:
            return b"", 0.0
        got = b""
        with contextlib.suppress(TimeoutError, ConnectionResetError):
            while True:
                chunk = s.recv(65536)
                if not chunk:
                    break
                got += chunk
    return got, time.monotonic() - t0
