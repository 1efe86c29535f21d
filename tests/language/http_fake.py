"""A local HTTP server that speaks the real wire protocols (Gemini generateContent, OpenAI chat
completions) and answers from a script, for the backend tests."""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


class Script:
    """Answers in order: ("text", str) | ("status", code) | ("sleep", seconds, str) | ("raw", str)."""

    def __init__(self, answers: list[tuple[Any, ...]]) -> None:
        self.answers = list(answers)
        self.requests: list[dict[str, Any]] = []

    def next(self) -> tuple[Any, ...]:
        return self.answers.pop(0) if len(self.answers) > 1 else self.answers[0]


def _gemini_body(text: str) -> dict[str, Any]:
    return {"candidates": [{"content": {"role": "model", "parts": [{"text": text}]}, "finishReason": "STOP",
                            "index": 0}],
            "usageMetadata": {"promptTokenCount": 10, "candidatesTokenCount": 5, "totalTokenCount": 15},
            "modelVersion": "gemini-2.5-flash-lite"}


def _openai_body(text: str) -> dict[str, Any]:
    return {"id": "chatcmpl-1", "object": "chat.completion", "created": 0, "model": "local",
            "choices": [{"index": 0, "message": {"role": "assistant", "content": text}, "finish_reason": "stop"}],
            "usage": {"prompt_tokens": 10, "completion_tokens": 5, "total_tokens": 15}}


@contextmanager
def serve(script: Script, protocol: str) -> Iterator[str]:
    """Run the fake server; yields its base URL."""

    class Handler(BaseHTTPRequestHandler):
        def log_message(self, *args: object) -> None:
            pass

        def do_POST(self) -> None:
            n = int(self.headers.get("content-length", 0))
            body = json.loads(self.rfile.read(n) or b"{}")
            script.requests.append({"path": self.path, "headers": dict(self.headers), "body": body})
            ans = script.next()
            if ans[0] == "sleep":
                time.sleep(ans[1])
                ans = ("text", ans[2])
            if ans[0] == "status":
                code = int(ans[1])
                if protocol == "gemini":
                    payload = {"error": {"code": code, "message": "quota exceeded" if code == 429 else "boom",
                                         "status": "RESOURCE_EXHAUSTED" if code == 429 else "INTERNAL"}}
                else:
                    payload = {"error": {"message": "rate limited", "type": "requests"}}
                self._send(code, payload, {"Retry-After": "0"} if code == 429 else {})
                return
            if ans[0] == "raw":
                self._send(200, None, raw=ans[1])
                return
            self._send(200, _gemini_body(ans[1]) if protocol == "gemini" else _openai_body(ans[1]))

        def _send(self, code: int, payload: Any, headers: dict[str, str] | None = None, raw: str | None = None
                  ) -> None:
            data = (raw if raw is not None else json.dumps(payload)).encode()
            self.send_response(code)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(data)))
            for k, v in (headers or {}).items():
                self.send_header(k, v)
            self.end_headers()
            try:
                self.wfile.write(data)
            except (BrokenPipeError, ConnectionResetError):
                pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    server.daemon_threads = True
    t = threading.Thread(target=server.serve_forever, daemon=True)
    t.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
