"""``capnav serve`` as a user runs it (a child process on a free loopback port): it says where it
serves once the socket accepts, reloads on SIGHUP, finishes an ask in progress on SIGTERM, and
refuses to listen off loopback without a token. ``capnav query --robot`` checks the position."""

from __future__ import annotations

import json
import os
import queue
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx

from capnav.io.mapfile import load_map, save_map


def _lines(proc: subprocess.Popen[str]) -> queue.Queue[str]:
    q: queue.Queue[str] = queue.Queue()

    def read() -> None:
        assert proc.stderr is not None
        for line in proc.stderr:
            q.put(line)

    threading.Thread(target=read, daemon=True).start()
    return q


def _wait_for(q: queue.Queue[str], pattern: str, timeout: float, seen: list[str]) -> re.Match[str]:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            line = q.get(timeout=0.5)
        except queue.Empty:
            continue
        seen.append(line)
        m = re.search(pattern, line)
        if m:
            return m
    raise AssertionError(f"no line matching {pattern!r} within {timeout} s; got {seen}")


def test_serve_listens_reloads_and_drains(served_map: Path, tmp_path: Path) -> None:
    path = tmp_path / "home.capnav"
    shutil.copy(served_map, path)
    proc = subprocess.Popen([sys.executable, "-m", "capnav.cli", "serve", str(path), "--port", "0", "--workers", "1"],
                            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=os.environ.copy())
    seen: list[str] = []
    try:
        q = _lines(proc)
        url = _wait_for(q, r"serving home \(7 objects\) on (http://\S+)/", 180, seen).group(1)
        assert httpx.get(url + "/healthz", timeout=5).status_code == 200  # it accepts as soon as it says so
        _wait_for(q, r"^ready: 1 map", 180, seen)
        assert httpx.get(url + "/readyz", timeout=5).status_code == 200

        cmap = load_map(served_map)
        cmap.objects = cmap.objects[:-1]
        save_map(cmap, path)
        proc.send_signal(signal.SIGHUP)
        _wait_for(q, r"SIGHUP: home: reloaded \(version 2, 6 objects\)", 60, seen)
        assert httpx.get(url + "/api/map", timeout=5).json()["objects"] == 6

        body = json.dumps({"text": "the red sofa", "robot": [6.0, 3.0]}).encode()
        host, port = url.removeprefix("http://").split(":")
        with socket.create_connection((host, int(port)), timeout=60) as s:
            s.sendall(b"POST /api/query HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                      + f"Content-Length: {len(body)}\r\n\r\n".encode() + body[:10])
            time.sleep(0.5)
            proc.send_signal(signal.SIGTERM)  # mid-request: the ask still gets its answer
            time.sleep(0.5)
            s.sendall(body[10:])
            got = b""
            while not got.endswith(b"}"):
                chunk = s.recv(65536)
                if not chunk:
                    break
                got += chunk
        assert got.startswith(b"HTTP/1.1 200") and b'"found":true' in got
        proc.wait(60)
        rest = proc.stderr.read() if proc.stderr else ""  # type: ignore[union-attr]
        assert "Traceback" not in "".join(seen) + rest
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_serve_off_loopback_needs_a_token(served_map: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "CAPNAV_SERVE_TOKEN"}
    r = subprocess.run([sys.executable, "-m", "capnav.cli", "serve", str(served_map), "--host", "0.0.0.0"],
                       capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 2 and "not loopback" in r.stderr and "--token" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_query_robot_is_checked_against_the_map(served_map: Path) -> None:
    cmd = [sys.executable, "-m", "capnav.cli", "query", str(served_map), "the red sofa", "--json"]
    r = subprocess.run([*cmd, "--robot", "500,-300"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--robot (500.00, -300.00) is off the map" in r.stderr
    r = subprocess.run([*cmd, "--robot", "3.8,6.0"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["chosen"]["id"] == 1 and "inside an obstacle; moved" in d["robot_note"]


def test_query_refuses_a_map_with_zero_embeddings(served_map: Path, tmp_path: Path) -> None:
    import numpy as np

    cmap = load_map(served_map)
    for o in cmap.objects:
        o.embedding = np.zeros_like(np.asarray(o.embedding))
    bad = save_map(cmap, tmp_path / "zero.capnav")
    r = subprocess.run([sys.executable, "-m", "capnav.cli", "query", str(bad), "the red sofa"], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 2 and "all-zero caption embeddings" in r.stderr and len(r.stderr.strip().splitlines()) == 1
