"""The cheapest cells of a target set from a start, one at a time, without searching the whole grid.

Goal selection wants the cheapest cell near an object that also passes a test too costly to run
on every candidate up front (a line of sight). ``NearestSearch`` is an A* towards the box that
holds the candidates (the octile distance to the box, times the smallest weight, is admissible
and consistent, and zero on every candidate), so candidates come out in increasing path cost; it
pauses at each candidate it settles and resumes from there when the caller rejects it. A
selection that accepts the first candidate it meets expands only the cells cheaper than it,
and those towards the object; exhausting the set costs one whole-grid Dijkstra, as before.

Moves and costs are those of :mod:`capnav.planning.search` (8-connected, the mean of the two
weights times the step length).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from capnav.planning.search import (
    _DC,
    _DR,
    _STEP,
    CLOSED,
    OPEN,
    SQRT2,
    TIE_BREAK,
    _grid,
    _grow,
    _min_finite,
    _pop,
    _push,
)


@njit(cache=True, nogil=True)
def _box_h(r: int, c: int, box: NDArray[np.int64]) -> float:
    dr = max(box[0] - r, 0, r - box[2])
    dc = max(box[1] - c, 0, c - box[3])
    lo = min(dr, dc)
    return (SQRT2 - 1.0) * lo + max(dr, dc)


@njit(cache=True, nogil=True)
def _resume(w: NDArray[np.floating], g: NDArray[np.float64], state: NDArray[np.uint8], hf: NDArray[np.float64],
            hi: NDArray[np.int64], size: int, target: NDArray[np.bool_], box: NDArray[np.int64], hscale: float
            ) -> tuple[int, int, NDArray[np.float64], NDArray[np.int64]]:
    """Run until a target cell is settled (returned after expanding it) or the heap is empty (-1)."""
    rows, cols = w.shape
    flat = w.ravel()
    while size > 0:
        u = _pop(hf, hi, size)
        size -= 1
        if state[u] == CLOSED:
            continue
        state[u] = CLOSED
        ur = u // cols
        uc = u - ur * cols
        wu = flat[u]
        gu = g[u]
        for k in range(8):
            vr = ur + _DR[k]
            vc = uc + _DC[k]
            if vr < 0 or vr >= rows or vc < 0 or vc >= cols:
                continue
            v = vr * cols + vc
            sv = state[v]
            wv = flat[v]
            if sv == CLOSED or not wv < np.inf:
                continue
            ng = gu + _STEP[k] * 0.5 * (wu + wv)
            if ng < (g[v] if sv == OPEN else np.inf):
                g[v] = ng
                state[v] = OPEN
                if size == hf.shape[0]:
                    hf, hi = _grow(hf, hi)
                _push(hf, hi, size, ng + hscale * _box_h(vr, vc, box), v)
                size += 1
        if target[u]:
            return u, size, hf, hi
    return -1, size, hf, hi


class NearestSearch:
    """Settle the cells of ``target`` (bool, the grid's shape, inside ``box`` = (r0, c0, r1, c1))
    in increasing path cost from ``start`` on ``weights``; ``next()`` gives the next one.
    ``min_weight`` (the smallest finite weight) saves a scan of the grid when the caller knows it."""

    def __init__(self, weights: NDArray[np.floating], start: tuple[int, int], target: NDArray[np.bool_],
                 box: tuple[int, int, int, int], min_weight: float | None = None) -> None:
        self.w = _grid(np.asarray(weights))  # a float32 costmap as it is: no copy per search
        rows, cols = self.w.shape
        n = rows * cols
        self.cols = cols
        self.g = np.empty(n, np.float64)
        self.state = np.zeros(n, np.uint8)
        self.target = np.ascontiguousarray(target, dtype=np.bool_).ravel()
        self.box = np.asarray(box, dtype=np.int64)
        # Ties of f broken towards deeper cells (as A* in search.py): far fewer expansions on open floor.
        self.hscale = (_min_finite(self.w.ravel()) if min_weight is None else min_weight) * (1.0 + TIE_BREAK)
        s = int(start[0]) * cols + int(start[1])
        self.g[s] = 0.0
        self.state[s] = OPEN
        self.hf = np.empty(4096, np.float64)
        self.hi = np.empty(4096, np.int64)
        _push(self.hf, self.hi, 0, 0.0, s)
        self.size = 1
        self.exhausted = False

    def next(self) -> tuple[tuple[int, int], float] | None:
        """The next cheapest target cell and its cost (in cells), or None when none is left."""
        if self.exhausted:
            return None
        u, self.size, self.hf, self.hi = _resume(self.w, self.g, self.state, self.hf, self.hi, self.size,
                                                 self.target, self.box, self.hscale)
        if u < 0:
            self.exhausted = True
            return None
        return (u // self.cols, u % self.cols), float(self.g[u])

    def finish(self) -> NDArray[np.float64]:
        """Search on to the end; the cost (rows, cols) of every settled cell, inf elsewhere."""
        none = np.zeros_like(self.target)
        if not self.exhausted:
            _resume(self.w, self.g, self.state, self.hf, self.hi, self.size, none, self.box, self.hscale)
            self.exhausted = True
        out = np.where(self.state == CLOSED, self.g, np.inf)
        return out.reshape(self.w.shape)

