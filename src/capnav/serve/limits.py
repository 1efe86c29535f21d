"""Request size and rate limits as plain ASGI middleware (no extra dependency).

A local map server still gets scripts that loop or paste a novel into the query box: bodies over
``max_body`` bytes get 413 before they are read whole, and each client address gets a token
bucket of ``burst`` requests refilled at ``rate`` per second (429 with ``Retry-After``).
"""

from __future__ import annotations

import json
import math
import threading
import time
from collections.abc import Awaitable, Callable, MutableMapping
from typing import Any

Scope = MutableMapping[str, Any]
Message = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]
ASGIApp = Callable[[Scope, Receive, Send], Awaitable[None]]


async def send_json(send: Send, status: int, body: dict[str, Any], headers: list[tuple[bytes, bytes]] | None = None
                    ) -> None:
    data = json.dumps(body).encode()
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(data)).encode()),
                            *(headers or [])]})
    await send({"type": "http.response.body", "body": data})


class _TooLarge(Exception):
    pass


class BodyLimit:
    """413 for a declared or streamed body larger than ``max_body`` bytes."""

    def __init__(self, app: ASGIApp, max_body: int) -> None:
        self.app = app
        self.max_body = int(max_body)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope.get("headers") or []).get(b"content-length")
        msg = {"error": f"request body over {self.max_body} bytes"}
        if declared is not None and declared.isdigit() and int(declared) > self.max_body:
            await send_json(send, 413, msg)
            return
        seen = 0
        started = False

        async def limited() -> Message:
            nonlocal seen
            m = await receive()
            if m["type"] == "http.request":
                seen += len(m.get("body", b""))
                if seen > self.max_body:
                    raise _TooLarge
            return m

        async def tracking(m: Message) -> None:
            nonlocal started
            started = started or m["type"] == "http.response.start"
            await send(m)

        try:
            await self.app(scope, limited, tracking)
        except _TooLarge:
            if not started:
                await send_json(send, 413, msg)


class RateLimit:
    """Token bucket per client address: ``burst`` requests at once, refilled at ``rate`` per second."""

    def __init__(self, app: ASGIApp, rate: float, burst: int, clock: Callable[[], float] = time.monotonic) -> None:
        self.app = app
        self.rate = float(rate)
        self.burst = max(1, int(burst))
        self.clock = clock
        self._buckets: dict[str, tuple[float, float]] = {}
        self._lock = threading.Lock()

    def take(self, client: str) -> float:
        """0 when the request may go on, else the seconds until a token is free."""
        now = self.clock()
        with self._lock:
            tokens, last = self._buckets.get(client, (float(self.burst), now))
            tokens = min(float(self.burst), tokens + (now - last) * self.rate)
            if tokens >= 1.0:
                self._buckets[client] = (tokens - 1.0, now)
                return 0.0
            self._buckets[client] = (tokens, now)
            if len(self._buckets) > 10_000:  # forget idle clients rather than grow without bound
                self._buckets = {k: v for k, v in self._buckets.items() if now - v[1] < 60.0}
            return (1.0 - tokens) / self.rate if self.rate > 0 else math.inf

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or self.rate <= 0:
            await self.app(scope, receive, send)
            return
        client = (scope.get("client") or ("?", 0))[0]
        wait = self.take(str(client))
        if wait > 0:
            retry = str(max(1, math.ceil(wait))) if math.isfinite(wait) else "60"
            await send_json(send, 429, {"error": f"too many requests from {client}: at most {self.rate:g} per "
                                                 f"second (burst {self.burst}); retry in {retry} s"},
                            [(b"retry-after", retry.encode())])
            return
        await self.app(scope, receive, send)
