"""Walking distances on a boolean grid: 8-connected moves (1 cell straight, sqrt 2 diagonal), from
many seed cells at once, and the smallest distance over each of many boxes.

Why a bucket queue and not a heap: every step costs at least one cell, so a cell whose distance
lies in [k, k + 1) can only be improved by cells closer than k, all of which are final once the
buckets before k are done (Dinitz's observation). The cells of one bucket are then expanded in
any order, each once, with no heap: a whole-grid search costs a few array reads per cell. The
values are the same floats a heap-ordered Dijkstra gives (each cell keeps the smallest
``d(neighbour) + step`` over its expanded neighbours, and rounding is monotone), so answers do
not move. Both kernels release the GIL: searches of several server threads run side by side.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

_DR = np.array([-1, -1, -1, 0, 0, 1, 1, 1], dtype=np.int64)
_DC = np.array([-1, 0, 1, -1, 1, -1, 0, 1], dtype=np.int64)
_STEP = np.array([1.4142135623730951, 1.0, 1.4142135623730951, 1.0, 1.0, 1.4142135623730951, 1.0,
                  1.4142135623730951])


@njit(cache=True, nogil=True)
def grid_geodesic(domain: NDArray[np.bool_], seeds: NDArray[np.int64], limit: float) -> NDArray[np.float64]:
    """Cells (float) from the nearest seed (row, col) to every cell through ``domain`` (True =
    walkable); inf where no walk reaches. Cells farther than ``limit`` are not expanded (a cell
    just past it keeps the value its expanded neighbours give it)."""
    rows, cols = domain.shape
    w = cols + 2  # a border of unwalkable cells: no bounds checks in the loop
    n = (rows + 2) * w
    # One byte per cell: 0 not walkable (or the border), 1 walkable, 2 expanded (final).
    state = np.zeros(n, np.uint8)
    for r in range(rows):
        for c in range(cols):
            if domain[r, c]:
                state[(r + 1) * w + c + 1] = 1
    off = np.empty(8, np.int64)
    for m in range(8):
        off[m] = _DR[m] * w + _DC[m]
    dist = np.full(n, np.inf)
    # Three buckets suffice: a cell expanded from bucket k lands in k + 1 or k + 2 (steps < 2).
    cap = 2 * rows * cols + seeds.shape[0] + 1
    buckets = np.empty((3, cap), np.int32)
    fill = np.zeros(3, np.int64)
    for i in range(seeds.shape[0]):
        u = (seeds[i, 0] + 1) * w + seeds[i, 1] + 1
        if dist[u] > 0.0:
            dist[u] = 0.0
            buckets[0, fill[0]] = u
            fill[0] += 1
    k = 0
    pending = fill[0]
    while pending > 0:
        b = k % 3
        j = 0
        while j < fill[b]:
            u = buckets[b, j]
            j += 1
            if state[u] == 2:
                continue
            state[u] = 2
            du = dist[u]
            if du > limit:
                continue
            for m in range(8):
                v = u + off[m]
                if state[v] != 1:
                    continue
                nd = du + _STEP[m]
                dv = dist[v]
                if nd < dv:
                    if dv == np.inf or int(dv) != int(nd):  # not in nd's bucket yet
                        bv = int(nd) % 3
                        buckets[bv, fill[bv]] = v
                        fill[bv] += 1
                        pending += 1
                    dist[v] = nd
        pending -= fill[b]
        fill[b] = 0
        k += 1
    out = np.empty((rows, cols))
    for r in range(rows):
        for c in range(cols):
            out[r, c] = dist[(r + 1) * w + c + 1]
    return out


@njit(cache=True, nogil=True)
def box_minima(field: NDArray[np.float64], boxes: NDArray[np.int64], grown: NDArray[np.int64], grow: float
               ) -> NDArray[np.float64]:
    """Per box (r0, c0, r1, c1 inclusive; empty when r1 < r0 or c1 < c0): the smallest value of
    ``field`` over its cells; when that is inf, over the ``grown`` box plus ``grow``; else inf."""
    out = np.full(boxes.shape[0], np.inf)
    for i in range(boxes.shape[0]):
        for g in range(2):
            bx = boxes[i] if g == 0 else grown[i]
            best = np.inf
            for r in range(bx[0], bx[2] + 1):
                for c in range(bx[1], bx[3] + 1):
                    if field[r, c] < best:
                        best = field[r, c]
            if best < np.inf:
                out[i] = best + (0.0 if g == 0 else grow)
                break
    return out


__all__ = ["box_minima", "grid_geodesic"]
