"""The server's edges as plain ASGI middleware: a body read deadline, one log line for a client
that leaves mid-request, a bearer token, and an access log.

A stalled body (headers sent, body never finished) would otherwise hold its request, and the
worker it waits for, as long as the client likes: ``BodyDeadline`` answers 408 and closes the
connection once ``timeout`` seconds pass without the whole body. The header-side twin (a client
that never finishes its headers) lives in ``serve.protocol``.
"""

from __future__ import annotations

import asyncio
import hmac
import logging
import time
from typing import Any

from starlette.requests import ClientDisconnect

from capnav.serve.limits import ASGIApp, Message, Receive, Scope, Send, send_json

log = logging.getLogger("capnav.serve")
access = logging.getLogger("capnav.serve.access")

#: Paths anyone may read even when a token is set: the page and its files (which then send the
#: token themselves) and the two probes (load balancers and watchdogs send no credentials).
OPEN_PATHS = ("/", "/healthz", "/readyz")


def _who(scope: Scope) -> str:
    c = scope.get("client")
    return f"{c[0]}:{c[1]}" if c else "a client"


class _Stalled(Exception):
    pass


class BodyDeadline:
    """408 and a closed connection when a request body is not complete ``timeout`` s after the
    request began; a client disconnect while its body is read is one log line, not a traceback."""

    def __init__(self, app: ASGIApp, timeout: float) -> None:
        self.app = app
        self.timeout = float(timeout)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        loop = asyncio.get_running_loop()
        deadline = loop.time() + self.timeout
        body_done = scope.get("method") in ("GET", "HEAD")
        started = False

        async def timed() -> Message:
            nonlocal body_done
            if body_done:
                return await receive()
            left = deadline - loop.time()
            try:
                if left <= 0:
                    raise TimeoutError
                m = await asyncio.wait_for(receive(), left)
            except TimeoutError:
                raise _Stalled from None
            if m["type"] != "http.request" or not m.get("more_body", False):
                body_done = True
            return m

        async def tracking(m: Message) -> None:
            nonlocal started
            started = started or m["type"] == "http.response.start"
            await send(m)

        try:
            await self.app(scope, timed, tracking)
        except _Stalled:
            log.info("%s sent no complete request body within %g s (%s %s): answered 408 and closed",
                     _who(scope), self.timeout, scope.get("method"), scope.get("path"))
            if not started:
                await send_json(send, 408, {"error": f"the request body did not arrive within {self.timeout:g} s"},
                                [(b"connection", b"close")])
        except ClientDisconnect:
            log.info("%s disconnected before its request was read (%s %s)", _who(scope), scope.get("method"),
                     scope.get("path"))


class BearerToken:
    """Every ``/api`` request must carry ``Authorization: Bearer TOKEN`` (401 otherwise)."""

    def __init__(self, app: ASGIApp, token: str) -> None:
        self.app = app
        self.token = token.encode()

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        path = scope.get("path", "")
        if scope["type"] != "http" or path in OPEN_PATHS or path.startswith("/static/"):
            await self.app(scope, receive, send)
            return
        got = b""
        for k, v in scope.get("headers") or []:
            if k == b"authorization" and v[:7].lower() == b"bearer ":
                got = v[7:].strip()
        if not hmac.compare_digest(got, self.token):
            await send_json(send, 401, {"error": "this server needs its bearer token: send 'Authorization: Bearer "
                                                 "TOKEN' (open the page as /#token=TOKEN)"},
                            [(b"www-authenticate", b'Bearer realm="capnav"')])
            return
        await self.app(scope, receive, send)


class AccessLog:
    """One line per request: method, path, status, milliseconds (``capnav serve --access-log``).

    The line is written before the last body chunk goes out, so a client that has its answer can
    already read the line (written after, it raced the client's next step)."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        t0 = time.perf_counter()
        status: list[Any] = [None]
        logged = [False]

        def line() -> None:
            if not logged[0]:
                logged[0] = True
                access.info("%s %s %s %.1f ms %s", scope.get("method"), scope.get("path"), status[0] or "-",
                            1e3 * (time.perf_counter() - t0), _who(scope))

        async def seen(m: Message) -> None:
            if m["type"] == "http.response.start":
                status[0] = m["status"]
            elif m["type"] == "http.response.body" and not m.get("more_body", False):
                line()
            await send(m)

        try:
            await self.app(scope, receive, seen)
        finally:
            line()
