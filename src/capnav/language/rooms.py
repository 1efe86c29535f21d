"""Geodesic distances on the top-down map, so that room cues do not leak through walls.

A cue object (a stove, a bed) says "kitchen" or "bedroom" to the objects it can be walked to in a
few metres, not to those behind a wall. Distances are computed through free space and furniture
(a sofa does not cut a room in two), never through walls: occupied cells that no object's box
covers. The grid's one-cell unsampled gaps are closed first (``fill_gaps``).
"""

from __future__ import annotations

import heapq

import numba
import numpy as np
from numpy.typing import NDArray

from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid


def fill_gaps(cells: NDArray[np.uint8], passes: int = 2) -> NDArray[np.uint8]:
    """Close one-cell UNKNOWN gaps whose two opposite neighbours agree (left/right or up/down).

    A grid finer than the voxels it was built from leaves such unsampled lines; left open they
    open holes in walls."""
    c = cells.copy()
    for _ in range(passes):
        unk = c == UNKNOWN
        if not unk.any():
            break
        pad = np.pad(c, 1, constant_values=UNKNOWN)
        left, right = pad[1:-1, :-2], pad[1:-1, 2:]
        down, up = pad[:-2, 1:-1], pad[2:, 1:-1]
        h = unk & (left == right) & (left != UNKNOWN)
        v = unk & ~h & (down == up) & (down != UNKNOWN)
        c[h] = left[h]
        c[v] = down[v]
    return c


def box_cells(spec: GridSpec, lo: NDArray[np.floating], hi: NDArray[np.floating],
              shrink: int = 0) -> tuple[int, int, int, int]:
    """Inclusive (r0, c0, r1, c1) cell range of a world box, clipped to the grid (may be empty)."""
    r0, c0 = spec.to_cell(np.asarray(lo, dtype=np.float64))
    r1, c1 = spec.to_cell(np.asarray(hi, dtype=np.float64))
    return (max(int(r0) + shrink, 0), max(int(c0) + shrink, 0),
            min(int(r1) - shrink, spec.rows - 1), min(int(c1) - shrink, spec.cols - 1))


def walkable_domain(occ: OccupancyGrid, boxes_lo: NDArray[np.float64], boxes_hi: NDArray[np.float64]
                    ) -> NDArray[np.bool_]:
    """Free cells plus the cells of object boxes (an object's own surface must not wall it in)."""
    cells = fill_gaps(occ.cells)
    dom = cells == FREE
    occupied = cells == OCCUPIED
    for lo, hi in zip(boxes_lo, boxes_hi, strict=True):
        r0, c0, r1, c1 = box_cells(occ.spec, lo, hi)
        if r1 >= r0 and c1 >= c0:
            dom[r0:r1 + 1, c0:c1 + 1] |= occupied[r0:r1 + 1, c0:c1 + 1]
    return dom


@numba.njit(cache=True)
def _dijkstra(domain: NDArray[np.bool_], seeds: NDArray[np.int64], limit: float) -> NDArray[np.float64]:
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


def geodesic_from_boxes(domain: NDArray[np.bool_], spec: GridSpec, los: NDArray[np.floating],
                        his: NDArray[np.floating], limit_m: float = 12.0) -> NDArray[np.float64]:
    """Metres from the nearest of several boxes to every cell through ``domain`` (inf where
    unreachable or beyond ``limit_m``): one multi-source Dijkstra."""
    seeds_list = []
    for lo, hi in zip(np.atleast_2d(los), np.atleast_2d(his), strict=True):
        r0, c0, r1, c1 = box_cells(spec, lo, hi)
        if r1 < r0 or c1 < c0:
            continue
        rr, cc = np.mgrid[r0:r1 + 1, c0:c1 + 1]
        seeds_list.append(np.stack([rr.ravel(), cc.ravel()], axis=1))
    if not seeds_list:
        return np.full(domain.shape, np.inf)
    seeds = np.concatenate(seeds_list).astype(np.int64)
    seeds = seeds[domain[seeds[:, 0], seeds[:, 1]]]
    if len(seeds) == 0:
        return np.full(domain.shape, np.inf)
    return _dijkstra(domain, seeds, limit_m / spec.resolution) * spec.resolution


def box_min(field: NDArray[np.float64], spec: GridSpec, lo: NDArray[np.floating], hi: NDArray[np.floating],
            ring: float = 0.3) -> float:
    """Smallest value of ``field`` over a box's cells (grown by ``ring`` m when all are inf)."""
    for grow in (0.0, ring):
        r0, c0, r1, c1 = box_cells(spec, np.asarray(lo) - grow, np.asarray(hi) + grow)
        if r1 >= r0 and c1 >= c0:
            v = float(field[r0:r1 + 1, c0:c1 + 1].min())
            if np.isfinite(v):
                return v + grow
    return float("inf")
