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
def _resume(w: NDArray[np.floating], g: NDArray[np.float64], state: NDArray[np.uint8], hf: NDArray[np.float64],
            hi: NDArray[np.int64], size: int, target: NDArray[np.bool_], box: NDArray[np.int64], hscale: float
            ) -> tuple[int, int, NDArray[np.float64], NDArray[np.int64]]:
    """Run until a target cell is settled (returned after expanding it) or the heap is empty (-1).
    ``target`` covers ``box`` only (its rows, cols): the cells outside it are never targets."""
    rows, cols = w.shape
    flat = w.ravel()
    r0, c0, r1, c1 = box[0], box[1], box[2], box[3]
    bw = c1 - c0 + 1
    off = np.empty(8, np.int64)
    for k in range(8):
        off[k] = _DR[k] * cols + _DC[k]
    while size > 0:
        u = _pop(hf, hi, size)
        size -= 1
        if state[u] == CLOSED:
            continue
        state[u] = CLOSED
        ur = u // cols
        uc = u - ur * cols
        edge = ur == 0 or uc == 0 or ur == rows - 1 or uc == cols - 1  # only then can a neighbour be off the grid
        wu = flat[u]
        gu = g[u]
        for k in range(8):
            vr = ur + _DR[k]
            vc = uc + _DC[k]
            if edge and (vr < 0 or vr >= rows or vc < 0 or vc >= cols):
                continue
            v = u + off[k]
            wv = flat[v]
            if not wv < np.inf:
                continue
            sv = state[v]
            if sv == CLOSED:
                continue
            ng = gu + _STEP[k] * 0.5 * (wu + wv)
            if ng < (g[v] if sv == OPEN else np.inf):
                g[v] = ng
                state[v] = OPEN
                if size == hf.shape[0]:
                    hf, hi = _grow(hf, hi)
                # The octile distance to the box, inline.
                dr = max(r0 - vr, 0, vr - r1)
                dc = max(c0 - vc, 0, vc - c1)
                _push(hf, hi, size, ng + hscale * ((SQRT2 - 1.0) * min(dr, dc) + max(dr, dc)), v)
                size += 1
        if r0 <= ur <= r1 and c0 <= uc <= c1 and target[(ur - r0) * bw + uc - c0]:
            return u, size, hf, hi
    return -1, size, hf, hi


class NearestSearch:
    """Settle the cells of ``target`` (bool, the grid's shape or the shape of ``box`` = (r0, c0, r1,
    c1) inclusive, all of its cells inside the box) in increasing path cost from ``start`` on
    ``weights``; ``next()`` gives the next one. ``min_weight`` (the smallest finite weight) saves a
    scan of the grid when the caller knows it."""

    def __init__(self, weights: NDArray[np.floating], start: tuple[int, int], target: NDArray[np.bool_],
                 box: tuple[int, int, int, int], min_weight: float | None = None) -> None:
        self.w = _grid(np.asarray(weights))  # a float32 costmap as it is: no copy per search
        rows, cols = self.w.shape
        n = rows * cols
        self.cols = cols
        self.g = np.empty(n, np.float64)
        self.state = np.zeros(n, np.uint8)
        self.box = np.asarray(box, dtype=np.int64)
        r0, c0, r1, c1 = (int(v) for v in self.box)
        t = np.asarray(target, dtype=np.bool_)
        if t.shape == self.w.shape:  # the whole grid: what lies outside the box is no target
            t = t[r0:r1 + 1, c0:c1 + 1]
        if t.shape != (r1 - r0 + 1, c1 - c0 + 1):
            raise ValueError(f"target must have the grid's shape {self.w.shape} or the box's "
                             f"{(r1 - r0 + 1, c1 - c0 + 1)}, got {t.shape}")
        self.target = np.ascontiguousarray(t).ravel()
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
        none = np.zeros_like(self.target)  # no target: on to the end
        if not self.exhausted:
            _resume(self.w, self.g, self.state, self.hf, self.hi, self.size, none, self.box, self.hscale)
            self.exhausted = True
        out = np.where(self.state == CLOSED, self.g, np.inf)
        return out.reshape(self.w.shape)

