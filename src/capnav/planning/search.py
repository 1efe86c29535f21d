"""Numba-compiled grid search: A* with a binary heap, a Dijkstra cost field and line of sight.

Weights are a float64 (rows, cols) array, ``inf`` where a cell is not traversable and >= 1
elsewhere. Moving between 8-connected neighbours a, b costs ``step * (w[a] + w[b]) / 2`` with
step 1 or sqrt(2) (the same rule as scikit-image's ``MCP_Geometric``), so with unit weights a path
cost is its octile length in cells. The octile distance times the smallest weight is then an
admissible, consistent heuristic, so A* returns the optimal cost.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

SQRT2 = float(np.sqrt(2.0))
_DR = np.array([-1, -1, -1, 0, 0, 1, 1, 1], dtype=np.int64)
_DC = np.array([-1, 0, 1, -1, 1, -1, 0, 1], dtype=np.int64)
_STEP = np.array([SQRT2, 1.0, SQRT2, 1.0, 1.0, SQRT2, 1.0, SQRT2], dtype=np.float64)


#: Heuristic inflation that breaks f-ties towards deeper nodes (far fewer expansions on open
#: floors); it bounds the cost excess by this relative amount, far below float noise in metres.
TIE_BREAK = 1e-9


@njit(cache=True)
def _grow(hf: NDArray[np.float64], hi: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    size = hf.shape[0]
    nf = np.empty(2 * size, np.float64)
    ni = np.empty(2 * size, np.int64)
    nf[:size] = hf
    ni[:size] = hi
    return nf, ni


@njit(cache=True, inline="always")
def _push(hf: NDArray[np.float64], hi: NDArray[np.int64], size: int, f: float, i: int) -> None:
    """Insert at ``size`` (capacity checked by the caller) and sift up."""
    k = size
    while k > 0:
        p = (k - 1) >> 1
        if f < hf[p]:
            hf[k] = hf[p]
            hi[k] = hi[p]
            k = p
        else:
            break
    hf[k] = f
    hi[k] = i


@njit(cache=True, inline="always")
def _pop(hf: NDArray[np.float64], hi: NDArray[np.int64], size: int) -> int:
    """Remove the minimum (heap of ``size`` items) and return its index."""
    top = hi[0]
    size -= 1
    f = hf[size]
    i = hi[size]
    k = 0
    while True:
        m = 2 * k + 1
        if m >= size:
            break
        if m + 1 < size and hf[m + 1] < hf[m]:
            m += 1
        if hf[m] < f:
            hf[k] = hf[m]
            hi[k] = hi[m]
            k = m
        else:
            break
    hf[k] = f
    hi[k] = i
    return top


@njit(cache=True)
def _octile(r: int, c: int, gr: int, gc: int) -> float:
    dr = abs(r - gr)
    dc = abs(c - gc)
    lo = min(dr, dc)
    return (SQRT2 - 1.0) * lo + max(dr, dc)


@njit(cache=True)
def _min_finite(flat: NDArray[np.float64]) -> float:
    m = np.inf
    for x in flat:
        if x < m:
            m = x
    return m if m < np.inf else 1.0


#: ``state`` of a cell during a search: never reached (its g and parent are garbage), in the
#: open heap, expanded. One byte per cell, so a query clears n bytes instead of 17n.
UNSEEN, OPEN, CLOSED = 0, 1, 2


@njit(cache=True)
def _search(w: NDArray[np.float64], start: int, goal: int, hscale: float
            ) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.uint8]]:
    """Best-first search from ``start``; stops at ``goal`` (or exhausts the grid when goal < 0).

    ``g`` and ``parent`` are left uninitialised and read only where ``state`` says a cell was
    reached (the grid is touched only where the search goes, as in pyastar2d)."""
    rows, cols = w.shape
    n = rows * cols
    flat = w.ravel()
    g = np.empty(n, np.float64)
    parent = np.empty(n, np.int64)
    state = np.zeros(n, np.uint8)
    hf = np.empty(4096, np.float64)
    hi = np.empty(4096, np.int64)
    hscale = hscale * (1.0 + TIE_BREAK)
    gr = goal // cols if goal >= 0 else 0
    gc = goal % cols if goal >= 0 else 0
    g[start] = 0.0
    parent[start] = -1
    state[start] = OPEN
    _push(hf, hi, 0, 0.0, start)
    size = 1
    while size > 0:
        u = _pop(hf, hi, size)
        size -= 1
        if state[u] == CLOSED:
            continue
        state[u] = CLOSED
        if u == goal:
            break
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
                parent[v] = u
                state[v] = OPEN
                f = ng + hscale * _octile(vr, vc, gr, gc) if goal >= 0 else ng
                if size == hf.shape[0]:
                    hf, hi = _grow(hf, hi)
                _push(hf, hi, size, f, v)
                size += 1
    return g, parent, state


@njit(cache=True)
def _field(g: NDArray[np.float64], parent: NDArray[np.int64], state: NDArray[np.uint8]) -> None:
    """Unreached cells: cost inf, parent -1 (the whole-grid answer of ``cost_field``)."""
    for i in range(g.shape[0]):
        if state[i] == UNSEEN:
            g[i] = np.inf
            parent[i] = -1


def astar(weights: NDArray[np.float64], start: tuple[int, int], goal: tuple[int, int]
          ) -> tuple[NDArray[np.intp], float]:
    """Optimal 8-connected path (cells (K, 2) row, col) and its cost; empty path when unreachable."""
    w = np.ascontiguousarray(weights, dtype=np.float64)
    cols = w.shape[1]
    s = int(start[0]) * cols + int(start[1])
    t = int(goal[0]) * cols + int(goal[1])
    g, parent, state = _search(w, s, t, _min_finite(w.ravel()))
    if state[t] == UNSEEN or not np.isfinite(g[t]):
        return np.empty((0, 2), np.intp), float("inf")
    return _backtrack(parent, t, cols), float(g[t])


def cost_field(weights: NDArray[np.float64], start: tuple[int, int]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Dijkstra from ``start`` over the whole grid: cost (rows, cols) and flat parent indices."""
    w = np.ascontiguousarray(weights, dtype=np.float64)
    g, parent, state = _search(w, int(start[0]) * w.shape[1] + int(start[1]), -1, 0.0)
    _field(g, parent, state)
    return g.reshape(w.shape), parent


@njit(cache=True)
def _backtrack_flat(parent: NDArray[np.int64], goal: int) -> NDArray[np.int64]:
    n = 0
    u = goal
    while u >= 0:
        n += 1
        u = parent[u]
    out = np.empty(n, np.int64)
    u = goal
    for k in range(n - 1, -1, -1):
        out[k] = u
        u = parent[u]
    return out


def _backtrack(parent: NDArray[np.int64], goal: int, cols: int) -> NDArray[np.intp]:
    idx = _backtrack_flat(parent, goal)
    return np.stack([idx // cols, idx % cols], axis=1).astype(np.intp)


def path_from_field(parent: NDArray[np.int64], goal: tuple[int, int], cols: int) -> NDArray[np.intp]:
    """Cells from the field's start to ``goal`` using the parent array of :func:`cost_field`."""
    return _backtrack(parent, int(goal[0]) * cols + int(goal[1]), cols)


@njit(cache=True)
def line_clear(w: NDArray[np.float64], r0: int, c0: int, r1: int, c1: int, wmax: float) -> bool:
    """True when every cell the segment between the two cell centres touches has weight <= wmax.

    An exact grid traversal (Amanatides-Woo); passing exactly through a corner checks both
    side cells, so a straight move never clips an obstacle corner.
    """
    dr = r1 - r0
    dc = c1 - c0
    sr = 1 if dr > 0 else -1
    sc = 1 if dc > 0 else -1
    t_dr = 1.0 / abs(dr) if dr != 0 else np.inf
    t_dc = 1.0 / abs(dc) if dc != 0 else np.inf
    t_r = 0.5 * t_dr
    t_c = 0.5 * t_dc
    r = r0
    c = c0
    if not w[r, c] <= wmax:
        return False
    while r != r1 or c != c1:
        if abs(t_r - t_c) < 1e-12:
            if not (w[r + sr, c] <= wmax and w[r, c + sc] <= wmax):
                return False
            r += sr
            c += sc
            t_r += t_dr
            t_c += t_dc
        elif t_r < t_c:
            r += sr
            t_r += t_dr
        else:
            c += sc
            t_c += t_dc
        if not w[r, c] <= wmax:
            return False
    return True


@njit(cache=True)
def _simplify(w: NDArray[np.float64], cells: NDArray[np.int64]) -> NDArray[np.int64]:
    n = cells.shape[0]
    keep = np.zeros(n, np.bool_)
    keep[0] = True
    keep[n - 1] = True
    anchor = 0
    wmax = w[cells[0, 0], cells[0, 1]]
    j = 1
    while j < n:
        wmax = max(wmax, w[cells[j, 0], cells[j, 1]])
        if not line_clear(w, cells[anchor, 0], cells[anchor, 1], cells[j, 0], cells[j, 1], wmax):
            anchor = j - 1
            keep[anchor] = True
            wmax = max(w[cells[anchor, 0], cells[anchor, 1]], w[cells[j, 0], cells[j, 1]])
        j += 1
    return np.nonzero(keep)[0]


def simplify(weights: NDArray[np.float64], cells: NDArray[np.integer]) -> NDArray[np.intp]:
    """Indices of the path cells kept as waypoints: a straight segment replaces a run of cells when
    it crosses no cell heavier than the heaviest cell of that run (so it never cuts through
    unknown space the search avoided)."""
    if len(cells) <= 2:
        return np.arange(len(cells), dtype=np.intp)
    w = np.ascontiguousarray(weights, dtype=np.float64)
    return _simplify(w, np.ascontiguousarray(cells, dtype=np.int64)).astype(np.intp)
