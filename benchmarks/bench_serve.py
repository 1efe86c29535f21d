"""Asking ``capnav serve`` from 1, 8 and 64 clients at once, with and without robot positions.

The map is bench_query.py's synthetic, seeded 300-object map (24 x 18 m), captioned offline and
saved to a temporary file; the server runs for real (``capnav serve`` in a child process on a free
loopback port, rate limit off, its default queue and ``--workers`` worker processes, or threads
with ``--pool threads``). For each row,
``clients`` concurrent keep-alive connections ask seeded instructions back to back for
``--warmup`` + ``--seconds`` seconds (default 1 + 5), and the row counts the asks that finish in
the last ``--seconds`` (``--seconds 0``: until ``--asks`` answers are in, as before: 200 asks last
about a second on an idle machine, too short for a stable 8-vs-1 ratio), while one more connection
polls ``/healthz``
every 20 ms from a process of its own (not behind the clients' event loop): a robot's watchdog,
which must not wait behind the asks. With a robot position the server also picks the goal pose
and plans the A* path to it; its own CPU time per ask is split into the ask (retrieval and, with
a robot, the goal pose) and the path. The warm-up asks every (instruction, robot position) pair
the rows time, so the server's per-start-cell caches (walking distances, goal poses) answer them;
``--new-robots`` gives every timed ask a position of its own (seeded per row) that no ask used
before, the cost for robots that have moved.

The clients are plain HTTP/1.1 over asyncio streams (``RawClient``: a request written as bytes,
the status line, headers and a Content-Length body read back, the answer's JSON decoded), and the
watchdog the same over a blocking socket: real requests on real connections, at a fraction of the
CPU of httpx, which bench_serve used before (an ask cost httpx more CPU than the server's event
loop spent on it, on the same 2 cores, so the 8-client rows measured the client too).

Printed per row: asks/s, p50/p95 latency, errors (any non-200), /healthz p95 during the burst,
the workers' CPU ms per ask (p50), the event loop thread's CPU per ask (with worker threads the
GIL it waits for is not counted), and the load average when the row ended (the machine may be
shared: read every figure beside it). Targets: 8 clients >= 1.6x one client's asks/s; /healthz
p95 < 50 ms during the 64-client burst; no errors; an ask with a robot position (retrieval and
goal pose, the path apart) <= 5 ms CPU p50.

    PYTHONPATH=src .venv/bin/python benchmarks/bench_serve.py [--objects 300] [--seconds 5] [--warmup 1]
        [--clients 1 8 64] [--seed 0] [--workers 2] [--pool processes|threads] [--cli-runs 3] [--new-robots]
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import itertools
import json
import multiprocessing as mp
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import httpx
import numpy as np

from bench_query import instructions, synthetic_map
from capnav.api import CapNav
from capnav.language import create_captioner, create_embedder, describe_map


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_ready(url: str, proc: subprocess.Popen[bytes], timeout: float = 300.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise SystemExit(f"capnav serve exited with {proc.returncode}")
        try:
            if httpx.get(url + "/readyz", timeout=2).status_code == 200:
                return
        except httpx.HTTPError:
            pass
        time.sleep(0.2)
    raise SystemExit(f"capnav serve was not ready within {timeout:.0f} s")


def loop_cpu(pid: int) -> float:
    """CPU seconds of the server's main thread (its event loop) so far (Linux /proc; nan elsewhere)."""
    try:
        fields = Path(f"/proc/{pid}/task/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return float("nan")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def load() -> float:
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")


CTX = mp.get_context("spawn")


def _head(raw: bytes) -> tuple[int, int, bool]:
    """Status, Content-Length and whether the server closes, from a response's header block."""
    lines = raw.decode("latin-1").split("\r\n")
    status = int(lines[0].split()[1])
    length, close = 0, False
    for line in lines[1:]:
        k, _, v = line.partition(":")
        k = k.strip().lower()
        if k == "content-length":
            length = int(v)
        elif k == "connection" and v.strip().lower() == "close":
            close = True
    return status, length, close


class RawClient:
    """One keep-alive HTTP/1.1 connection over asyncio streams (reopened when the server closes
    it): POST a JSON body, read the status and the Content-Length body."""

    def __init__(self, url: str, timeout: float = 120.0) -> None:
        host, port = url.removeprefix("http://").rstrip("/").rsplit(":", 1)
        self.host, self.port, self.timeout = host, int(port), timeout
        self.reader: asyncio.StreamReader | None = None
        self.writer: asyncio.StreamWriter | None = None

    async def post(self, path: str, body: Any) -> tuple[int, bytes]:
        data = json.dumps(body, separators=(",", ":")).encode()
        req = (f"POST {path} HTTP/1.1\r\nhost: {self.host}:{self.port}\r\ncontent-type: application/json\r\n"
               f"content-length: {len(data)}\r\n\r\n").encode() + data
        return await asyncio.wait_for(self._exchange(req), self.timeout)

    async def _exchange(self, req: bytes) -> tuple[int, bytes]:
        if self.writer is None:
            self.reader, self.writer = await asyncio.open_connection(self.host, self.port)
        assert self.reader is not None
        try:
            self.writer.write(req)
            status, length, close = _head(await self.reader.readuntil(b"\r\n\r\n"))
            payload = await self.reader.readexactly(length)
        except BaseException:
            await self.close()
            raise
        if close:
            await self.close()
        return status, payload

    async def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
            with contextlib.suppress(OSError):
                await self.writer.wait_closed()
        self.reader = self.writer = None


def _get(sock: socket.socket, buf: bytearray, host: str, path: str) -> int:
    """GET on a blocking keep-alive socket; the status (``buf`` keeps what follows the response)."""
    sock.sendall(f"GET {path} HTTP/1.1\r\nhost: {host}\r\n\r\n".encode())
    while (end := buf.find(b"\r\n\r\n")) < 0:
        chunk = sock.recv(65536)
        if not chunk:
            raise ConnectionError("the server closed the connection")
        buf += chunk
    status, length, _ = _head(bytes(buf[:end]))
    del buf[:end + 4]
    while len(buf) < length:
        chunk = sock.recv(65536)
        if not chunk:
            raise ConnectionError("the server closed the connection")
        buf += chunk
    del buf[:length]
    return status


def watchdog(url: str, stop: Any, conn: Any) -> None:
    """A robot's watchdog in a process of its own (not behind the clients' event loop): GET
    /healthz every 20 ms until ``stop``; sends back the seconds each took."""
    took: list[float] = []
    host, port = url.removeprefix("http://").rstrip("/").rsplit(":", 1)
    buf = bytearray()
    with socket.create_connection((host, int(port)), timeout=30) as sock:
        _get(sock, buf, host, "/healthz")
        conn.send("polling")
        while not stop.is_set():
            t0 = time.perf_counter()
            _get(sock, buf, host, "/healthz")
            took.append(time.perf_counter() - t0)
            time.sleep(0.02)
    conn.send(took)


async def warm(url: str, qs: list[tuple[str, list[float]]], workers: int) -> None:
    """Ask every instruction as many times as there are workers (they share one queue), with and
    without the robot, untimed: every row then meets the caches a running server has (verifier
    judgements per object), not only the rows after the first."""
    async with httpx.AsyncClient(base_url=url, timeout=120) as c:
        async def one(k: int) -> None:
            for text, xy in qs[k::workers]:
                for body in ({"text": text, "k": 5}, {"text": text, "k": 5, "robot": xy}):
                    await c.post("/api/query", json=body)

        for _ in range(workers):
            await asyncio.gather(*(one(k) for k in range(workers)))


def positions(n: int, seed: int) -> list[list[float]]:
    """``n`` robot positions on the map, seeded: with ``--new-robots`` one per ask, so a row of any
    length meets start cells no ask before it used (0.05 m cells: a repeat is rare)."""
    rng = np.random.default_rng(seed)
    return [[float(rng.uniform(0.5, 23.5)), float(rng.uniform(0.5, 17.5))] for _ in range(n)]


async def burst(url: str, qs: list[tuple[str, list[float]]], clients: int, asks: int, robot: bool, pid: int,
                seconds: float = 0.0, warmup: float = 1.0, fresh: int | None = None) -> dict[str, float]:
    """One row. With ``seconds`` > 0 the clients ask for ``warmup`` + ``seconds`` and the row's
    figures are those of the asks that finished in the last ``seconds`` (the steady part: the
    connections open, the workers busy); else until ``asks`` answers are in. ``fresh`` (a seed):
    every ask gets a robot position of its own instead of its instruction's."""
    total = max(asks, 4 * clients)
    done: list[tuple[float, float, float, float]] = []  # (finished at, latency, ask CPU, path CPU)
    errors = 0
    counter = itertools.count()
    news = positions(200_000 if seconds > 0 else total, fresh) if fresh is not None else None
    t_start = t_end = 0.0

    async def client(c: RawClient) -> None:
        nonlocal errors
        for i in counter:
            if seconds > 0:
                if time.perf_counter() >= t_end:
                    return
            elif i >= total:
                return
            text, xy = qs[i % len(qs)]
            if news is not None:
                xy = news[i % len(news)]
            body = {"text": text, "k": 5, **({"robot": xy} if robot else {})}
            t0 = time.perf_counter()
            try:
                status, payload = await c.post("/api/query", body)
            except (OSError, asyncio.IncompleteReadError, asyncio.LimitOverrunError, TimeoutError, ValueError):
                errors += 1
                continue
            t1 = time.perf_counter()
            if status != 200:
                errors += 1
                continue
            ms = json.loads(payload)["server_ms"]
            done.append((t1, t1 - t0, ms["ask_cpu"], ms["plan_cpu"]))

    conns = [RawClient(url) for _ in range(clients)]
    try:
        # Open the connections (their first requests), one per client.
        await asyncio.gather(*(c.post("/api/query", {"text": qs[k % len(qs)][0], "k": 5})
                               for k, c in enumerate(conns)))
        stop, (mine, theirs) = CTX.Event(), CTX.Pipe()
        dog = CTX.Process(target=watchdog, args=(url, stop, theirs), daemon=True)
        dog.start()
        mine.recv()  # polling
        t_start = time.perf_counter()
        t_end = t_start + warmup + seconds
        l0 = loop_cpu(pid)
        if seconds > 0:
            tasks = [asyncio.ensure_future(client(c)) for c in conns]
            await asyncio.sleep(warmup)
            l0, t0 = loop_cpu(pid), time.perf_counter()
            await asyncio.sleep(max(t_end - t0, 0.0))
            wall, loop_s = time.perf_counter() - t0, loop_cpu(pid) - l0
            await asyncio.gather(*tasks)  # the asks in flight at the end, not counted
            done = [d for d in done if t0 <= d[0] <= t0 + wall]
        else:
            t0 = t_start
            await asyncio.gather(*(client(c) for c in conns))
            wall, loop_s = time.perf_counter() - t0, loop_cpu(pid) - l0
        stop.set()
        health = mine.recv()
        dog.join(30)
    finally:
        for c in conns:
            await c.close()
    ms = np.asarray([d[1] for d in done]) * 1e3
    cpu_ask = [d[2] for d in done]
    cpu_plan = [d[3] for d in done]
    return {"n": len(done), "rate": len(done) / wall, "p50": float(np.percentile(ms, 50)) if len(ms) else float("nan"),
            "p95": float(np.percentile(ms, 95)) if len(ms) else float("nan"), "errors": errors,
            "health95": float(np.percentile(np.asarray(health) * 1e3, 95)) if health else float("nan"),
            "ask_cpu": float(np.median(cpu_ask)) if cpu_ask else float("nan"),
            "plan_cpu": float(np.median(cpu_plan)) if cpu_plan else float("nan"), "load": load(),
            "loop_cpu": loop_s * 1e3 / max(len(done), 1)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--objects", type=int, default=300)
    ap.add_argument("--asks", type=int, default=200,
                    help="answers per row (at least 4 per client) when --seconds is 0")
    ap.add_argument("--seconds", type=float, default=5.0,
                    help="each row asks for --warmup + this many seconds and counts the asks that finish in "
                         "the last SECONDS (0: rows of --asks answers, as before)")
    ap.add_argument("--warmup", type=float, default=1.0, help="seconds of each row not counted (with --seconds)")
    ap.add_argument("--clients", type=int, nargs="*", default=[1, 8, 64])
    ap.add_argument("--workers", type=int, default=2, help="the server's workers")
    ap.add_argument("--pool", choices=["processes", "threads"], default="processes", help="the server's pool")
    ap.add_argument("--cli-runs", type=int, default=3, help="one-shot `capnav query` runs for reference (0: none)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--new-robots", action="store_true",
                    help="give every timed ask a robot position of its own, never asked before (seeded per row): "
                         "the server's per-start-cell caches miss, as for robots that moved since they last asked")
    args = ap.parse_args()

    cmap = synthetic_map(args.objects, args.seed)
    describe_map(cmap, None, create_captioner("offline"), create_embedder("minilm"), progress=False)
    rng = np.random.default_rng(args.seed + 1)
    qs = [(text, [float(rng.uniform(0.5, 23.5)), float(rng.uniform(0.5, 17.5))])
          for text, _ in instructions(args.asks, args.seed)]
    rows: list[tuple[int, bool, dict[str, float]]] = []
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.capnav"
        CapNav(cmap).save(path)
        port = free_port()
        url = f"http://127.0.0.1:{port}"
        proc = subprocess.Popen([sys.executable, "-m", "capnav.cli", "serve", str(path), "--port", str(port),
                                 "--rate", "0", "--workers", str(args.workers), "--pool", args.pool],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            wait_ready(url, proc)
            asyncio.run(warm(url, qs, args.workers))
            for robot in (False, True):
                for clients in args.clients:
                    # --new-robots: a seed of the row's own, so no row meets the cells another used.
                    fresh = 1000 * (args.seed + 1) + 2 * clients + robot if args.new_robots else None
                    rows.append((clients, robot, asyncio.run(burst(url, qs, clients, args.asks, robot, proc.pid,
                                                                   args.seconds, args.warmup, fresh))))
                    r = rows[-1][2]
                    print(f"# {clients} clients, robot {robot}: {r['rate']:.1f} asks/s (load {r['load']:.1f})",
                          file=sys.stderr, flush=True)
        finally:
            proc.terminate()
            proc.wait(timeout=60)
        cli_s = []
        for text, robot_xy in qs[: args.cli_runs]:
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "capnav.cli", "query", str(path), text, "--robot",
                            f"{robot_xy[0]},{robot_xy[1]}", "--json"], check=True, capture_output=True)
            cli_s.append(time.perf_counter() - t0)

    print(f"{args.objects}-object synthetic map (seed {args.seed}), {len(qs)} instructions, server with "
          f"{args.workers} worker {args.pool}, {os.cpu_count()} CPUs (shared: load average per row)")
    print()
    print("| clients | robot | asks | asks/s | p50 ms | p95 ms | errors | /healthz p95 ms | worker CPU ms/ask p50 "
          "(ask; path) | event loop CPU ms/ask | load |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---:|")
    for clients, robot, r in rows:
        cpu = f"{r['ask_cpu']:.1f}; {r['plan_cpu']:.1f}" if robot else f"{r['ask_cpu']:.1f}; -"
        print(f"| {clients} | {'yes' if robot else 'no'} | {r['n']:.0f} | {r['rate']:.1f} | {r['p50']:.1f} | "
              f"{r['p95']:.1f} | {r['errors']:.0f} | {r['health95']:.1f} | {cpu} | {r['loop_cpu']:.1f} | "
              f"{r['load']:.1f} |")
    if cli_s:
        cm = np.asarray(cli_s) * 1e3
        print(f"\none-shot `capnav query --json --robot` for reference: {np.median(cm):.0f} ms wall median of "
              f"{len(cli_s)} runs")
    print()
    by = {(c, rb): r for c, rb, r in rows}
    for robot in (False, True):
        if (1, robot) in by and (8, robot) in by:
            one, eight = by[(1, robot)], by[(8, robot)]
            gain = eight["rate"] / max(one["rate"], 1e-9)
            print(f"target 8 clients >= 1.6x one client's asks/s (robot {'yes' if robot else 'no'}): "
                  f"{eight['rate']:.1f} / {one['rate']:.1f} = {gain:.2f}x {'met' if gain >= 1.6 else 'NOT met'} "
                  f"(load {one['load']:.1f} / {eight['load']:.1f})")
    for robot in (False, True):
        if (64, robot) in by:
            h = by[(64, robot)]["health95"]
            print(f"target /healthz p95 < 50 ms during 64 clients (robot {'yes' if robot else 'no'}): {h:.1f} ms "
                  f"{'met' if h < 50 else 'NOT met'}")
    for clients in (1, 8, 64):
        if (clients, True) in by:
            c = by[(clients, True)]["ask_cpu"]
            print(f"target ask with a robot position <= 5 ms CPU p50 ({clients} clients): {c:.1f} ms "
                  f"{'met' if c <= 5 else 'NOT met'}")
            break
    errs = sum(r["errors"] for _, _, r in rows)
    print(f"target no errors: {errs:.0f} {'met' if errs == 0 else 'NOT met'}")


if __name__ == "__main__":
    main()
