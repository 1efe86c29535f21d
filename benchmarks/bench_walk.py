"""Walking distances from a robot's cell to every object of bench_query.py's seeded 300-object map
(24 x 18 m at 5 cm: 368 x 488 cells), as "the closest chair" with a robot position needs them.

Ours: ``capnav.core.geodesic.walk_box_minima`` (a bucket queue: every step costs >= 1 cell, so a
bucket's cells are final and need no heap; on the padded grid ``FloorDistances`` makes once per
map, with the minima over the objects' boxes taken without making the whole field), i.e.
``FloorDistances.from_point`` without its cache. Reference, same run: the heap-ordered Dijkstra
(numba, a list of tuples through ``heapq``) it replaced, with the per-object Python loop of
``rooms.box_min``. Both must give the same floats (checked on every source). CPU time per call
(``time.thread_time``), p50 and p95 over ``--sources`` random free cells.

    .venv/bin/python benchmarks/bench_walk.py [--objects 300] [--sources 40] [--seed 0]
"""

from __future__ import annotations

import argparse
import heapq
import os
import time

import numba
import numpy as np
from numpy.typing import NDArray

from bench_query import synthetic_map
from capnav.core.geodesic import walk_box_minima
from capnav.language.rooms import box_min
from capnav.retrieval.spatial import RING, FloorDistances


@numba.njit(cache=True)
def heap_dijkstra(domain: NDArray[np.bool_], seeds: NDArray[np.int64], limit: float) -> NDArray[np.float64]:
    rows, cols = domain.shape
    dist = np.full((rows, cols), np.inf)
    heap = [(0.0, np.int64(0), np.int64(0))]
    heap.pop()
    for k in range(seeds.shape[0]):
        r, c = seeds[k, 0], seeds[k, 1]
        dist[r, c] = 0.0
        heap.append((0.0, r, c))
    heapq.heapify(heap)
    dr = np.array([-1, -1, -1, 0, 0, 1, 1, 1])
    dc = np.array([-1, 0, 1, -1, 1, -1, 0, 1])
    w = np.array([1.4142135623730951, 1.0, 1.4142135623730951, 1.0, 1.0, 1.4142135623730951, 1.0,
                  1.4142135623730951])
    while len(heap) > 0:
        d, r, c = heapq.heappop(heap)
        if d > dist[r, c] or d > limit:
            continue
        for k in range(8):
            rr, cc = r + dr[k], c + dc[k]
            if rr < 0 or cc < 0 or rr >= rows or cc >= cols or not domain[rr, cc]:
                continue
            nd = d + w[k]
            if nd < dist[rr, cc]:
                dist[rr, cc] = nd
                heapq.heappush(heap, (nd, rr, cc))
    return dist


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--objects", type=int, default=300)
    ap.add_argument("--sources", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    cmap = synthetic_map(args.objects, args.seed)
    los = np.array([o.extent_min[:2] for o in cmap.objects])
    his = np.array([o.extent_max[:2] for o in cmap.objects])
    floor = FloorDistances(cmap.occupancy, los, his)
    spec, dom = floor.spec, floor.domain
    free = np.argwhere(dom)
    rng = np.random.default_rng(args.seed)
    sources = free[rng.choice(len(free), size=args.sources, replace=False)].astype(np.int64)
    ours_ms: list[float] = []
    ref_ms: list[float] = []
    warm = sources[:1]
    def ours_fn(seed: NDArray[np.int64]) -> NDArray[np.float64]:
        return walk_box_minima(floor._base, spec.cols, seed, floor._boxes, floor._grown, spec.resolution, RING)

    ours_fn(warm)
    heap_dijkstra(dom, warm, np.inf)
    for s in sources:
        seed = s.reshape(1, 2)
        c0 = time.thread_time()
        ours = ours_fn(seed)
        c1 = time.thread_time()
        field = heap_dijkstra(dom, seed, np.inf) * spec.resolution
        ref = np.array([box_min(field, spec, lo, hi, RING) for lo, hi in zip(los, his, strict=True)])
        c2 = time.thread_time()
        if not np.array_equal(ours, ref):
            raise SystemExit(f"different distances from cell {tuple(s)}")
        ours_ms.append((c1 - c0) * 1e3)
        ref_ms.append((c2 - c1) * 1e3)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{args.objects}-object synthetic map (seed {args.seed}), {dom.shape[0]} x {dom.shape[1]} cells, "
          f"{args.sources} sources; CPU ms per source, load average {load:.1f}")
    print()
    print("| distances from a cell to every object | p50 ms | p95 ms |")
    print("|---|---:|---:|")
    for name, v in (("bucket queue with box minima, one kernel (ours)", ours_ms),
                    ("heap Dijkstra + per-object loop (reference)", ref_ms)):
        print(f"| {name} | {np.percentile(v, 50):.2f} | {np.percentile(v, 95):.2f} |")
    print(f"\nsame floats on all {args.sources} sources; speed-up at p50 "
          f"{np.percentile(ref_ms, 50) / np.percentile(ours_ms, 50):.1f}x")


if __name__ == "__main__":
    main()
