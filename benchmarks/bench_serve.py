"""Asking through ``capnav serve`` against asking with the one-shot ``capnav query`` command.

The server keeps the map, the embedder and the planner's costmap loaded, so an ask costs the
query itself plus one loopback HTTP round trip; the command loads Python, the map and the
embedder on every call. The map is bench_query.py's synthetic, seeded 300-object map, captioned
offline and saved to a temporary file; the server runs for real (uvicorn on a free loopback port,
rate limit off) and is asked over one keep-alive connection, each instruction twice: as an ask
(retrieval: which object, why, runners-up) and as an ask with a robot position, for which the
server also picks a goal pose (a Dijkstra search over the whole 24 x 18 m grid) and plans the A*
path to it. Target: ask p95 <= 50 ms.

    .venv/bin/python benchmarks/bench_serve.py [--objects 300] [--queries 200] [--cli-runs 3] [--seed 0]
"""

from __future__ import annotations

import argparse
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import httpx
import numpy as np

from bench_query import instructions, synthetic_map
from capnav.api import CapNav
from capnav.language import create_captioner, create_embedder, describe_map


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_ready(url: str, proc: subprocess.Popen[bytes], timeout: float = 120.0) -> None:
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
    raise SystemExit(f"capnav serve did not answer within {timeout:.0f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--objects", type=int, default=300)
    ap.add_argument("--queries", type=int, default=200)
    ap.add_argument("--cli-runs", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    cmap = synthetic_map(args.objects, args.seed)
    describe_map(cmap, None, create_captioner("offline"), create_embedder("minilm"), progress=False)
    rng = np.random.default_rng(args.seed + 1)
    qs = [(text, [float(rng.uniform(0.5, 23.5)), float(rng.uniform(0.5, 17.5))])
          for text, _ in instructions(args.queries, args.seed)]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.capnav"
        CapNav(cmap).save(path)
        port = free_port()
        url = f"http://127.0.0.1:{port}"
        proc = subprocess.Popen([sys.executable, "-m", "capnav.cli", "serve", str(path), "--port", str(port),
                                 "--rate", "0"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            wait_ready(url, proc)
            ask_s: list[float] = []
            plan_s: list[float] = []
            server_ms: list[float] = []
            found = planned = 0
            with httpx.Client(base_url=url, timeout=30) as client:
                for text, robot in qs[:5]:  # first requests of a connection
                    client.post("/api/query", json={"text": text, "k": 5, "robot": robot})
                for text, robot in qs:
                    t0 = time.perf_counter()
                    r = client.post("/api/query", json={"text": text, "k": 5})
                    ask_s.append(time.perf_counter() - t0)
                    r.raise_for_status()
                    d = r.json()
                    found += d["found"]
                    server_ms.append(d["server_ms"]["cpu"])
                    t0 = time.perf_counter()
                    r = client.post("/api/query", json={"text": text, "k": 5, "robot": robot})
                    plan_s.append(time.perf_counter() - t0)
                    r.raise_for_status()
                    planned += r.json()["plan"] is not None
        finally:
            proc.terminate()
            proc.wait(timeout=20)
        cli_s = []
        for text, robot in qs[: args.cli_runs]:
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "capnav.cli", "query", str(path), text, "--robot",
                            f"{robot[0]},{robot[1]}", "--json"], check=True, capture_output=True)
            cli_s.append(time.perf_counter() - t0)

    ms = np.asarray(ask_s) * 1e3
    pm = np.asarray(plan_s) * 1e3
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{args.objects}-object synthetic map (seed {args.seed}), {len(qs)} instructions ({found} found; "
          f"{planned} of the asks with a robot position planned a path); load average {load:.1f} on "
          f"{os.cpu_count()} CPUs")
    print()
    print("| what | p50 ms | p95 ms | max ms |")
    print("|---|---:|---:|---:|")
    print(f"| ask through `capnav serve` (HTTP on loopback) | {np.percentile(ms, 50):.1f} | "
          f"{np.percentile(ms, 95):.1f} | {ms.max():.1f} |")
    rt = np.asarray(server_ms)
    print(f"| of which CPU time in the server's handler (retrieval) | {np.percentile(rt, 50):.1f} | "
          f"{np.percentile(rt, 95):.1f} | {rt.max():.1f} |")
    print(f"| ask with a robot position: + goal pose + A* path | {np.percentile(pm, 50):.1f} | "
          f"{np.percentile(pm, 95):.1f} | {pm.max():.1f} |")
    cm = np.asarray(cli_s) * 1e3
    print(f"| one-shot `capnav query --json` wall time ({len(cli_s)} runs, reference) | {np.median(cm):.0f} | "
          f"{cm.max():.0f} | {cm.max():.0f} |")
    print()
    print(f"target: ask p95 <= 50 ms: {'met' if np.percentile(ms, 95) <= 50 else 'NOT met'}")


if __name__ == "__main__":
    main()
