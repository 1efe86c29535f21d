"""Walking distances on a boolean grid: 8-connected moves (1 cell straight, sqrt 2 diagonal), from
many seed cells at once, and the smallest distance over each of many boxes.

Why a bucket queue and not a heap: every step costs at least one cell, so a cell whose distance
lies in [k, k + 1) can only be improved by cells closer than k, all of which are final once the
buckets before k are done (Dinitz's observation). The cells of one bucket are then expanded in
any order, each once, with no heap: a whole-grid search costs a few array reads per cell. The
values are the same floats a heap-ordered Dijkstra gives (each cell keeps the smallest
``d(neighbour) + step`` over its expanded neighbours, and rounding is monotone), so answers do
not move. Walking distances to objects are exact (``a + b sqrt 2`` from a walk's step counts,
``_walk_until``): the same float whichever end the walk starts from, so an object's
:func:`walk_field`, walked once from the object, answers a robot anywhere with the float a walk
from the robot gives.

Why one array: the distances live on the grid padded by a border, with ``BLOCKED`` (-1) in
unwalkable and border cells, so a neighbour is tested with the one read ``d + step < dist[v]``
(false for a blocked cell, and for an expanded one: its distance is below any step from the
bucket being expanded). A cell's entry in bucket k is stale when its distance has since dropped
below k (it was expanded from an earlier bucket). The padded grid of a domain
(:func:`walk_base`) is made once per map and copied per search. Every kernel releases the GIL:
searches of several server threads run side by side.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

_SQRT2 = 1.4142135623730951
#: The padded distance of a cell no walk enters (below every distance, so never "improved").
BLOCKED = -1.0


@njit(cache=True, nogil=True)
def walk_base(domain: NDArray[np.bool_]) -> NDArray[np.float64]:
    """The padded, flattened start of a search on ``domain`` (True = walkable): inf on walkable
    cells, ``BLOCKED`` on the others and on a one-cell border (no bounds checks in the search)."""
    rows, cols = domain.shape
    w = cols + 2
    base = np.full((rows + 2) * w, BLOCKED)
    for r in range(rows):
        o = (r + 1) * w + 1
        for c in range(cols):
            if domain[r, c]:
                base[o + c] = np.inf
    return base


@njit(cache=True, nogil=True)
def _walk(base: NDArray[np.float64], cols: int, seeds: NDArray[np.int64], limit: float) -> NDArray[np.float64]:
    """Cells from the nearest seed, on a copy of ``base`` (padded, ``cols`` + 2 wide)."""
    return _walk_until(base, cols, seeds, limit, np.zeros(0, np.uint8), np.zeros((0, 4), np.int64), False)[0]


@njit(cache=True, nogil=True)
def _walk_until(base: NDArray[np.float64], cols: int, seeds: NDArray[np.int64], limit: float,
                mark: NDArray[np.uint8], want: NDArray[np.int64], exact: bool
                ) -> tuple[NDArray[np.float64], bool, NDArray[np.int32]]:
    """``_walk``, stopped once a cell of every box of ``want`` (r0, c0, r1, c1 inclusive, grid
    cells; ``mark`` is 1 on their padded cells, or empty for no stop) is expanded; whether it ran
    to the end. When the last box's first cell is expanded at ``d`` in bucket k, every cell below
    k + 1 already holds its final distance (set from buckets before k) and every other cell holds
    at least k + 1 > ``d``: each box's minimum over ``dist`` is then final.

    ``exact``: each distance is ``a + b * sqrt 2`` computed from its walk's counts of straight
    (a) and diagonal (b) steps (returned as ``diag``, b per padded cell), not summed step by step:
    the float then depends on the counts only, so a walk from A to B and one from B to A give
    the same float (sums of the same steps in another order may differ in their last bit). Two
    different counts never tie and keep their order as floats: a + b sqrt 2 = a' + b' sqrt 2
    only when a = a', b = b' (sqrt 2 is irrational), and on any grid that fits in memory the
    gap between two such values is far above float64's rounding."""
    w = cols + 2
    dist = base.copy()
    diag = np.zeros(base.shape[0] if exact else 0, np.int32)
    left = want.shape[0]
    done = np.zeros(left, np.bool_)
    # Three buckets suffice: a cell expanded from bucket k lands in k + 1 or k + 2 (steps < 2); a
    # bucket holds a cell at most once. They rotate (the one done becomes k + 3's), so a push
    # picks its bucket by one comparison, with no modulo.
    n = base.shape[0] + seeds.shape[0] + 1
    cur = np.empty(n, np.int32)
    nx1 = np.empty(n, np.int32)
    nx2 = np.empty(n, np.int32)
    fc = 0
    for i in range(seeds.shape[0]):
        u = (seeds[i, 0] + 1) * w + seeds[i, 1] + 1
        if dist[u] != 0.0:  # a seed starts the walk even where the domain is not walkable
            dist[u] = 0.0
            cur[fc] = u
            fc += 1
    f1 = 0
    f2 = 0
    k = 0
    while fc + f1 + f2 > 0:
        k1 = k + 1
        kf = float(k)
        for j in range(fc):
            u = cur[j]
            du = dist[u]
            # Stale (expanded from an earlier bucket: below k, since it entered this one at >= k),
            # or too far.
            if du < kf or du > limit:
                continue
            if left > 0 and mark[u]:  # u is final: the boxes that hold it have their minimum
                ur = u // w - 1
                uc = u - (ur + 1) * w - 1
                for i in range(want.shape[0]):
                    if not done[i] and want[i, 0] <= ur <= want[i, 2] and want[i, 1] <= uc <= want[i, 3]:
                        done[i] = True
                        left -= 1
                if left == 0:
                    return dist, False, diag
            bu = diag[u] if exact else 0
            au = int(np.rint(du - bu * _SQRT2)) if exact else 0
            for m in range(8):
                if m == 0:
                    v, nd = u - w - 1, du + _SQRT2
                elif m == 1:
                    v, nd = u - w, du + 1.0
                elif m == 2:
                    v, nd = u - w + 1, du + _SQRT2
                elif m == 3:
                    v, nd = u - 1, du + 1.0
                elif m == 4:
                    v, nd = u + 1, du + 1.0
                elif m == 5:
                    v, nd = u + w - 1, du + _SQRT2
                elif m == 6:
                    v, nd = u + w, du + 1.0
                else:
                    v, nd = u + w + 1, du + _SQRT2
                dv = dist[v]
                if exact:
                    bv = bu + (1 if m == 0 or m == 2 or m == 5 or m == 7 else 0)
                    nd = float(au + bu + 1 - bv) + float(bv) * _SQRT2
                if nd < dv:
                    if exact:
                        diag[v] = bv
                    b = int(nd)
                    if dv == np.inf or int(dv) != b:  # not in nd's bucket yet
                        if b == k1:
                            nx1[f1] = v
                            f1 += 1
                        else:
                            nx2[f2] = v
                            f2 += 1
                    dist[v] = nd
        cur, nx1, nx2 = nx1, nx2, cur
        fc, f1, f2 = f1, f2, 0
        k += 1
    return dist, True, diag


@njit(cache=True, nogil=True)
def grid_geodesic(domain: NDArray[np.bool_], seeds: NDArray[np.int64], limit: float) -> NDArray[np.float64]:
    """Cells (float) from the nearest seed (row, col) to every cell through ``domain`` (True =
    walkable); inf where no walk reaches. Cells farther than ``limit`` are not expanded (a cell
    just past it keeps the value its expanded neighbours give it)."""
    rows, cols = domain.shape
    dist = _walk(walk_base(domain), cols, seeds, limit)
    out = np.empty((rows, cols))
    w = cols + 2
    for r in range(rows):
        o = (r + 1) * w + 1
        for c in range(cols):
            d = dist[o + c]
            out[r, c] = d if d >= 0.0 else np.inf
    return out


@njit(cache=True, nogil=True)
def _padded_min(dist: NDArray[np.float64], w: int, bx: NDArray[np.int64]) -> float:
    best = np.inf
    for r in range(bx[0], bx[2] + 1):
        o = (r + 1) * w + 1
        for c in range(bx[1], bx[3] + 1):
            d = dist[o + c]
            if d >= 0.0 and d < best:
                best = d
    return best


@njit(cache=True, nogil=True)
def walk_box_minima(base: NDArray[np.float64], cols: int, seeds: NDArray[np.int64], boxes: NDArray[np.int64],
                    grown: NDArray[np.int64], scale: float, grow: float) -> NDArray[np.float64]:
    """``box_minima`` of the walk from ``seeds`` on ``base`` (:func:`walk_base` of a grid ``cols``
    wide) times ``scale``, without making the (rows, cols) field: the same floats, since scaling by
    a positive number keeps the minimum (rounding is monotone). Distances are exact (see
    ``_walk_until``): the floats :func:`walk_field` gives from the box back to the seed."""
    dist = _walk_until(base, cols, seeds, np.inf, np.zeros(0, np.uint8), np.zeros((0, 4), np.int64), True)[0]
    w = cols + 2
    out = np.full(boxes.shape[0], np.inf)
    for i in range(boxes.shape[0]):
        best = _padded_min(dist, w, boxes[i])
        if best < np.inf:
            out[i] = best * scale
            continue
        best = _padded_min(dist, w, grown[i])
        if best < np.inf:
            out[i] = best * scale + grow
    return out


@njit(cache=True, nogil=True)
def walk_box_minima_of(base: NDArray[np.float64], cols: int, seeds: NDArray[np.int64], boxes: NDArray[np.int64],
                       grown: NDArray[np.int64], scale: float, grow: float, among: NDArray[np.int64]
                       ) -> NDArray[np.float64]:
    """``walk_box_minima`` for the boxes ``among`` only (nan for the others), the walk stopped
    once each of them holds an expanded cell: "the closest chair" needs the chairs, not the
    floor beyond the farthest one. The same floats for ``among``; when a box of them is never
    reached the walk runs to the end and every box gets its value."""
    w = cols + 2
    mark = np.zeros(base.shape[0], np.uint8)
    want = np.empty((among.shape[0], 4), np.int64)
    m = 0
    for j in range(among.shape[0]):
        bx = boxes[among[j]]
        if bx[2] < bx[0] or bx[3] < bx[1]:
            continue  # an empty box holds no cell: it cannot stop the walk
        want[m] = bx
        m += 1
        for r in range(bx[0], bx[2] + 1):
            o = (r + 1) * w + 1
            for c in range(bx[1], bx[3] + 1):
                mark[o + c] = 1
    if m < among.shape[0]:  # an empty box is reached only through its ring: the whole walk
        m = 0
    dist, whole, _ = _walk_until(base, cols, seeds, np.inf, mark, want[:m], True)
    out = np.full(boxes.shape[0], np.nan)
    for j in range(boxes.shape[0] if whole else 0):
        out[j] = np.inf
    for j in range(boxes.shape[0] if whole else among.shape[0]):
        i = j if whole else among[j]
        best = _padded_min(dist, w, boxes[i])
        if best < np.inf:
            out[i] = best * scale
        elif whole:
            best = _padded_min(dist, w, grown[i])
            if best < np.inf:
                out[i] = best * scale + grow
    return out


#: A cell of a walk field that no walk from its seeds reaches.
NO_WALK = np.uint32(0xFFFFFFFF)


@njit(cache=True, nogil=True)
def walk_field(base: NDArray[np.float64], cols: int, seeds: NDArray[np.int64]) -> NDArray[np.uint32]:
    """The exact walk from ``seeds`` (an object's cells) to every cell of the grid, kept as its
    step counts: ``a << 16 | b`` (a straight, b diagonal steps; the distance is
    :func:`walk_value`), ``NO_WALK`` where no walk reaches. Walks are symmetric, so the value
    at a robot's cell is the walk from the robot to the nearest seed: the float
    :func:`walk_box_minima_of` gives. Empty when a count does not fit in 16 bits."""
    w = cols + 2
    rows = base.shape[0] // w - 2
    dist, _, diag = _walk_until(base, cols, seeds, np.inf, np.zeros(0, np.uint8), np.zeros((0, 4), np.int64), True)
    out = np.empty(rows * cols, np.uint32)
    for r in range(rows):
        o = (r + 1) * w + 1
        for c in range(cols):
            d = dist[o + c]
            if d >= 0.0 and d < np.inf:
                b = diag[o + c]
                a = int(np.rint(d - b * _SQRT2))
                if a >= 65535 or b >= 65535:
                    return np.empty(0, np.uint32)
                out[r * cols + c] = (np.uint32(a) << np.uint32(16)) | np.uint32(b)
            else:
                out[r * cols + c] = NO_WALK
    return out


def walk_value(packed: int) -> float:
    """The distance (cells) of a :func:`walk_field` entry: a + b sqrt 2, as the walk computes it."""
    return float(packed >> 16) + float(packed & 0xFFFF) * _SQRT2


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


__all__ = ["BLOCKED", "NO_WALK", "box_minima", "grid_geodesic", "walk_base", "walk_box_minima", "walk_box_minima_of",
           "walk_field", "walk_value"]
