"""Running the app under uvicorn: a header read deadline, "serving on" once the socket listens,
SIGHUP as a reload, and SIGTERM as a drain (uvicorn's own graceful shutdown, then the pool's).

uvicorn's keep-alive timeout closes idle connections, but a client that sends half its headers
and waits is held forever; ``HeaderDeadline`` closes such a connection ``header_timeout`` seconds
after it opened (or after its previous response).
"""

from __future__ import annotations

import asyncio
import logging
import signal
import socket
import threading
from collections.abc import Callable
from typing import Any

import h11
import uvicorn
from uvicorn.protocols.http.h11_impl import H11Protocol

log = logging.getLogger("capnav.serve")


def header_protocol(header_timeout: float) -> type[H11Protocol]:
    """uvicorn's h11 protocol with a deadline on each request's headers."""

    class HeaderDeadline(H11Protocol):
        _header_timer: asyncio.TimerHandle | None = None

        def _arm(self) -> None:
            self._disarm()
            self._header_timer = self.loop.call_later(header_timeout, self._headers_late)

        def _disarm(self) -> None:
            if self._header_timer is not None:
                self._header_timer.cancel()
                self._header_timer = None

        def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
            super().connection_made(transport)
            self._arm()

        def connection_lost(self, exc: Exception | None) -> None:
            self._disarm()
            super().connection_lost(exc)

        def data_received(self, data: bytes) -> None:
            super().data_received(data)
            if self.conn.their_state is not h11.IDLE:
                self._disarm()  # the headers are in

        def on_response_complete(self) -> None:
            super().on_response_complete()
            if not self.transport.is_closing():
                self._arm()

        def _headers_late(self) -> None:
            self._header_timer = None
            if self.conn.their_state is h11.IDLE and not self.transport.is_closing():
                c = self.client
                log.info("%s sent no complete request headers within %g s: connection closed",
                         f"{c[0]}:{c[1]}" if c else "a client", header_timeout)
                self.transport.close()

    return HeaderDeadline


class Server(uvicorn.Server):
    """uvicorn's server that says where it listens once it does, and reloads on SIGHUP."""

    def __init__(self, config: uvicorn.Config, on_listen: Callable[[str], None],
                 on_sighup: Callable[[], Any] | None = None) -> None:
        super().__init__(config)
        self._on_listen = on_listen
        self._on_sighup = on_sighup
        self.loop: asyncio.AbstractEventLoop | None = None

    async def startup(self, sockets: list[socket.socket] | None = None) -> None:
        await super().startup(sockets)
        if not self.started or self.should_exit:
            return
        loop = self.loop = asyncio.get_running_loop()
        if self._on_sighup is not None and hasattr(signal, "SIGHUP") \
                and threading.current_thread() is threading.main_thread():
            hup = self._on_sighup

            def on_hup(*_: Any) -> None:
                loop.call_soon_threadsafe(lambda: loop.create_task(hup()))

            signal.signal(signal.SIGHUP, on_hup)
        for s in self.servers:
            for sock in s.sockets or []:
                host, port = sock.getsockname()[:2]
                shown = f"[{host}]" if ":" in host else host
                self._on_listen(f"http://{shown}:{port}/")
                return
