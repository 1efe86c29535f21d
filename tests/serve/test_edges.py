"""The server's edges through a real uvicorn on loopback, with small configured limits: JSON
bounds, stalled headers and bodies, client disconnects, a full or late pool, the access log, the
bearer token. Bounds in the checks are generous (the machine may be loaded); none measures speed."""

from __future__ import annotations

import asyncio
import logging
import threading
import time
from pathlib import Path

import httpx
import pytest

from capnav.serve import ServeConfig, create_app
from serve.live import live, raw

LIMITS = ServeConfig(max_depth=8, max_elements=50, body_timeout=1.0, workers=1, queue=1, time_limit=1.5,
                     access_log=True, rate=0)


@pytest.fixture(scope="module")
def server(served_map: Path):
    with live(create_app(served_map, LIMITS), header_timeout=1.0) as (url, srv):
        yield url, srv


def test_json_nesting_and_element_counts_are_bounded(server) -> None:
    url, _ = server
    r = httpx.post(url + "/api/query", content=b"[" * 5000 + b"]" * 5000, headers={"content-type": "application/json"})
    assert r.status_code == 400 and "nests 5000 levels deep; at most 8" in r.json()["error"]
    r = httpx.post(url + "/api/query", json={"text": "the sofa", "x": [[[[[[[[[1]]]]]]]]]})
    assert r.status_code == 400 and "at most 8" in r.json()["error"]
    r = httpx.post(url + "/api/query", json={"text": "the sofa", "x": list(range(60))})
    assert r.status_code == 400 and "at most 50" in r.json()["error"]
    r = httpx.post(url + "/api/query", json={"text": "the [[[[[[[[[[ sofa"})  # brackets in strings do not nest
    assert r.status_code == 200 and r.json()["found"]


def test_a_stalled_body_is_cut(server, caplog: pytest.LogCaptureFixture) -> None:
    url, _ = server
    caplog.set_level(logging.INFO, logger="capnav.serve")
    got, took = raw(url, b"POST /api/query HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                         b"Content-Length: 100\r\n\r\n{\"te")
    assert b" 408 " in got.split(b"\r\n")[0] and b"did not arrive within 1 s" in got
    assert took < 10.0  # cut at the 1 s deadline, not held open
    assert any("no complete request body within 1 s" in r.getMessage() for r in caplog.records)


def test_stalled_headers_close_the_connection(server) -> None:
    url, _ = server
    got, took = raw(url, b"GET /healthz HTTP/1.1\r\nHo")
    assert got == b"" and took < 10.0


def test_a_client_that_leaves_mid_body_is_one_log_line(server, caplog: pytest.LogCaptureFixture) -> None:
    url, _ = server
    caplog.set_level(logging.INFO)
    raw(url, b"POST /api/query HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: 100\r\n\r\n"
             b"{\"text\"", then_close=True)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and not any("disconnected" in r.getMessage() for r in caplog.records):
        time.sleep(0.05)
    lines = [r for r in caplog.records if "disconnected" in r.getMessage()]
    assert len(lines) == 1 and "before its request was read (POST /api/query)" in lines[0].getMessage()
    assert not [r for r in caplog.records if r.exc_info]  # no traceback anywhere


def test_full_or_late_pool_is_503_while_health_answers(server) -> None:
    url, srv = server
    app_pool = srv.config.app.state.pool  # type: ignore[union-attr]
    release = threading.Event()
    assert srv.loop is not None
    blocker = asyncio.run_coroutine_threadsafe(app_pool.run(lambda st, dl: release.wait(30), 60.0), srv.loop)
    try:
        deadline = time.monotonic() + 10
        while app_pool.in_flight < 1 and time.monotonic() < deadline:
            time.sleep(0.02)
        out: dict[str, httpx.Response] = {}
        late = threading.Thread(target=lambda: out.setdefault(
            "late", httpx.post(url + "/api/query", json={"text": "the red sofa"}, timeout=30)))
        late.start()  # admitted to the one queue place, then waits past the 1.5 s limit
        while app_pool.in_flight < 2 and time.monotonic() < deadline:
            time.sleep(0.02)
        r = httpx.post(url + "/api/query", json={"text": "the red sofa"}, timeout=30)
        assert r.status_code == 503 and "busy" in r.json()["error"] and r.headers["retry-after"] == "1"
        t0 = time.monotonic()
        assert httpx.get(url + "/healthz", timeout=5).status_code == 200  # the loop is free
        assert httpx.get(url + "/api/map", timeout=5).status_code == 200
        assert httpx.get(url + "/readyz", timeout=5).json()["in_flight"] == 2
        assert time.monotonic() - t0 < 5
        late.join(30)
        assert out["late"].status_code == 503 and "time limit of 1.5 s" in out["late"].json()["error"]
    finally:
        release.set()
        blocker.result(30)
    assert httpx.post(url + "/api/query", json={"text": "the red sofa"}, timeout=30).status_code == 200


def test_access_log_line_per_request(server, caplog: pytest.LogCaptureFixture) -> None:
    url, _ = server
    caplog.set_level(logging.INFO, logger="capnav.serve.access")
    httpx.get(url + "/api/objects")
    httpx.get(url + "/api/maps/nope/objects")
    msgs = [r.getMessage() for r in caplog.records if r.name == "capnav.serve.access"]
    assert any(m.startswith("GET /api/objects 200 ") and " ms " in m for m in msgs)
    assert any(m.startswith("GET /api/maps/nope/objects 404 ") for m in msgs)


def test_bearer_token(served_map: Path) -> None:
    cfg = ServeConfig(token="s3cret-token", warm_up=False, workers=1)
    with live(create_app(served_map, cfg)) as (url, _):
        assert httpx.get(url + "/healthz").status_code == 200 and httpx.get(url + "/").status_code == 200
        r = httpx.get(url + "/api/map")
        assert r.status_code == 401 and "bearer token" in r.json()["error"]
        assert "Bearer" in r.headers["www-authenticate"]
        assert httpx.get(url + "/api/map", headers={"authorization": "Bearer wrong-token"}).status_code == 401
        ok = httpx.get(url + "/api/map", headers={"authorization": "Bearer s3cret-token"})
        assert ok.status_code == 200 and ok.json()["objects"] == 7
