"""Numba-compiled grid search: A* with a binary heap, a Dijkstra cost field and line of sight.

Weights are a float32 or float64 (rows, cols) array, ``inf`` where a cell is not traversable and
>= 1 elsewhere (``build_costmap`` makes float32: half the memory the search walks). Moving
between 8-connected neighbours a, b costs ``step * (w[a] + w[b]) / 2`` with step 1 or sqrt(2)
(the same rule as scikit-image's ``MCP_Geometric``), so with unit weights a path cost is its
octile length in cells. The octile distance times the smallest weight is then an admissible,
consistent heuristic, so A* returns the optimal cost.

A search touches only the cells it reaches, as pyastar2d's does, and nothing per call scans the
grid: the smallest weight and the work arrays (cost, parent, a visit stamp per cell, the heap)
are kept per weight array and reused by the next search on it. The stamp of a cell says whether
this search has seen it, so it is cleared only once every 126 searches. Weights may be raised in place
between searches (``mark_blocked``: the kept minimum stays a lower bound); after lowering any,
call :func:`forget`. The kernels release the GIL, so threads with their own weight arrays search
in parallel.
"""

from __future__ import annotations

import threading
import weakref
from dataclasses import dataclass, field

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


@njit(cache=True, nogil=True)
def _kgrow(heap: NDArray[np.int64]) -> NDArray[np.int64]:
    out = np.empty(2 * heap.shape[0], np.int64)
    out[:heap.shape[0]] = heap
    return out


@njit(cache=True, nogil=True, inline="always")
def _kpush(heap: NDArray[np.int64], size: int, key: int) -> None:
    """Insert at ``size`` (capacity checked by the caller) and sift up a 4-ary heap (half the
    levels of a binary one: fewer moves on each push and pop)."""
    k = size
    while k > 0:
        p = (k - 1) >> 2
        if key < heap[p]:
            heap[k] = heap[p]
            k = p
        else:
            break
    heap[k] = key


@njit(cache=True, nogil=True, inline="always")
def _kpop(heap: NDArray[np.int64], size: int) -> int:
    """Remove the smallest key (4-ary heap of ``size`` items) and return it."""
    top = heap[0]
    size -= 1
    key = heap[size]
    k = 0
    while True:
        c = 4 * k + 1
        if c >= size:
            break
        m = c
        best = heap[c]
        end = min(c + 4, size)
        for j in range(c + 1, end):
            if heap[j] < best:
                best = heap[j]
                m = j
        if best < key:
            heap[k] = best
            k = m
        else:
            break
    heap[k] = key
    return top


@njit(cache=True, nogil=True)
def _grow(hf: NDArray[np.float64], hi: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """A (priority, cell) heap in two arrays, for searches that keep their own state
    (``planning.nearest``)."""
    size = hf.shape[0]
    nf = np.empty(2 * size, np.float64)
    ni = np.empty(2 * size, np.int64)
    nf[:size] = hf
    ni[:size] = hi
    return nf, ni


@njit(cache=True, nogil=True, inline="always")
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


@njit(cache=True, nogil=True, inline="always")
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


#: ``state`` of a cell in a search that keeps a byte per cell (``planning.nearest``).
UNSEEN, OPEN, CLOSED = 0, 1, 2


@njit(cache=True, nogil=True)
def _octile(r: int, c: int, gr: int, gc: int) -> float:
    dr = abs(r - gr)
    dc = abs(c - gc)
    lo = min(dr, dc)
    return (SQRT2 - 1.0) * lo + max(dr, dc)


@njit(cache=True, nogil=True)
def _min_finite(flat: NDArray[np.floating]) -> float:
    m = np.inf
    for x in flat:
        if x < m:
            m = x
    return float(m) if m < np.inf else 1.0


@njit(cache=True, nogil=True)
def _search(w: NDArray[np.floating], start: int, goal: int, hscale: float, g: NDArray[np.float64],
            parent: NDArray[np.int32], stamp: NDArray[np.uint8], gen: int, heap: NDArray[np.int64]
            ) -> tuple[float, NDArray[np.int64]]:
    """Best-first search from ``start``; stops at ``goal`` (or exhausts the grid when goal < 0).

    ``stamp[v] == gen``: v is open in this search (its g and parent are valid); ``gen + 1``: v is
    expanded; anything else: not reached (its g and parent are left from an earlier search).
    A heap key is the priority's float64 bit pattern (ordered as an integer for priorities >= 0)
    with its lowest bits replaced by the cell index: one 8-byte array instead of two, at a
    priority resolution of 2**(bits - 52) relative. Returns the goal's cost (inf when
    unreachable) and the heap array (grown if needed)."""
    rows, cols = w.shape
    n = rows * cols
    flat = w.ravel()
    opened = np.uint8(gen)
    closed = np.uint8(gen + 1)
    bits = 1
    while (1 << bits) < n:
        bits += 1
    mask = np.int64((1 << bits) - 1)
    keep = ~mask
    fb = np.empty(1, np.float64)
    ib = fb.view(np.int64)
    off = np.empty(8, np.int64)
    for k in range(8):
        off[k] = _DR[k] * cols + _DC[k]
    hscale = hscale * (1.0 + TIE_BREAK)
    gr = goal // cols if goal >= 0 else 0
    gc = goal % cols if goal >= 0 else 0
    g[start] = 0.0
    parent[start] = -1
    stamp[start] = opened
    heap[0] = start
    size = 1
    while size > 0:
        u = _kpop(heap, size) & mask
        size -= 1
        if stamp[u] == closed:
            continue
        stamp[u] = closed
        if u == goal:
            return g[u], heap
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
            sv = stamp[v]
            if sv == closed:
                continue
            ng = gu + _STEP[k] * 0.5 * (wu + wv)
            if sv != opened or ng < g[v]:
                g[v] = ng
                parent[v] = u
                stamp[v] = opened
                fb[0] = ng + hscale * _octile(vr, vc, gr, gc) if goal >= 0 else ng
                if size == heap.shape[0]:
                    heap = _kgrow(heap)
                _kpush(heap, size, (ib[0] & keep) | v)
                size += 1
    return np.inf, heap


@dataclass(eq=False)
class _Work:
    """The arrays one weight grid's searches reuse, and its smallest weight."""

    wmin: float
    g: NDArray[np.float64]
    parent: NDArray[np.int32]
    stamp: NDArray[np.uint8]
    heap: NDArray[np.int64] = field(default_factory=lambda: np.empty(4096, np.int64))
    gen: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    @classmethod
    def new(cls, w: NDArray[np.floating]) -> _Work:
        n = w.size
        return cls(_min_finite(w.ravel()), np.empty(n, np.float64), np.empty(n, np.int32), np.zeros(n, np.uint8))

    def next_gen(self) -> int:
        """Stamps are one byte: after 126 searches they are cleared (n bytes, once per 126 searches)."""
        self.gen += 2
        if self.gen >= 254:
            self.stamp.fill(0)
            self.gen = 2
        return self.gen


_WORK: dict[int, tuple[weakref.ref[NDArray[np.floating]], _Work]] = {}
_WORK_LOCK = threading.Lock()


def _grid(weights: NDArray[np.floating]) -> NDArray[np.floating]:
    if weights.ndim != 2:
        raise ValueError(f"weights must be a (rows, cols) array, got shape {weights.shape}")
    if weights.size >= 2**31:
        raise ValueError(f"a grid of {weights.size} cells is too large for the search (at most 2**31 - 1)")
    if weights.dtype in (np.float32, np.float64) and weights.flags.c_contiguous:
        return weights
    return np.ascontiguousarray(weights, dtype=np.float32 if weights.dtype == np.float32 else np.float64)


def _work_for(w: NDArray[np.floating]) -> _Work:
    """The kept arrays of weight grid ``w`` (made on its first search, dropped with ``w``)."""
    key = id(w)
    with _WORK_LOCK:
        have = _WORK.get(key)
        if have is not None and have[0]() is w and have[1].g.shape[0] == w.size:
            return have[1]
        work = _Work.new(w)

        def gone(_: object, k: int = key) -> None:
            _WORK.pop(k, None)

        _WORK[key] = (weakref.ref(w, gone), work)
        return work


def forget(weights: NDArray[np.floating]) -> None:
    """Drop what is kept for ``weights`` (after lowering weights in place)."""
    with _WORK_LOCK:
        _WORK.pop(id(weights), None)


def _run(w: NDArray[np.floating], start: int, goal: int, heuristic: bool
         ) -> tuple[float, _Work, int, bool]:
    """One search on ``w``'s kept arrays (fresh ones when another thread holds them)."""
    work = _work_for(w)
    mine = work.lock.acquire(blocking=False)
    if not mine:
        work = _Work(work.wmin, np.empty(w.size, np.float64), np.empty(w.size, np.int32), np.zeros(w.size, np.uint8))
    try:
        gen = work.next_gen()
        cost, work.heap = _search(w, start, goal, work.wmin if heuristic else 0.0, work.g, work.parent,
                                  work.stamp, gen, work.heap)
    except BaseException:
        if mine:
            work.lock.release()
        raise
    return cost, work, gen, mine


def astar(weights: NDArray[np.floating], start: tuple[int, int], goal: tuple[int, int]
          ) -> tuple[NDArray[np.intp], float]:
    """Optimal 8-connected path (cells (K, 2) row, col) and its cost; empty path when unreachable."""
    w = _grid(np.asarray(weights))
    cols = w.shape[1]
    s = int(start[0]) * cols + int(start[1])
    t = int(goal[0]) * cols + int(goal[1])
    cost, work, _, mine = _run(w, s, t, True)
    try:
        if not np.isfinite(cost):
            return np.empty((0, 2), np.intp), float("inf")
        return _backtrack(work.parent, t, cols), float(cost)
    finally:
        if mine:
            work.lock.release()


def cost_field(weights: NDArray[np.floating], start: tuple[int, int]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Dijkstra from ``start`` over the whole grid: cost (rows, cols) and flat parent indices
    (-1 where unreached), as new arrays the caller owns."""
    w = _grid(np.asarray(weights))
    _, work, gen, mine = _run(w, int(start[0]) * w.shape[1] + int(start[1]), -1, False)
    try:
        reached = work.stamp == np.uint8(gen + 1)
        g = np.where(reached, work.g, np.inf)
        parent = np.where(reached, work.parent, -1).astype(np.int64)
    finally:
        if mine:
            work.lock.release()
    return g.reshape(w.shape), parent


@njit(cache=True, nogil=True)
def _backtrack_flat(parent: NDArray[np.integer], goal: int) -> NDArray[np.int64]:
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


def _backtrack(parent: NDArray[np.integer], goal: int, cols: int) -> NDArray[np.intp]:
    idx = _backtrack_flat(parent, goal)
    return np.stack([idx // cols, idx % cols], axis=1).astype(np.intp)


def path_from_field(parent: NDArray[np.int64], goal: tuple[int, int], cols: int) -> NDArray[np.intp]:
    """Cells from the field's start to ``goal`` using the parent array of :func:`cost_field`."""
    return _backtrack(parent, int(goal[0]) * cols + int(goal[1]), cols)


@njit(cache=True, nogil=True)
def line_clear(w: NDArray[np.floating], r0: int, c0: int, r1: int, c1: int, wmax: float) -> bool:
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


@njit(cache=True, nogil=True)
def _simplify(w: NDArray[np.floating], cells: NDArray[np.int64]) -> NDArray[np.int64]:
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


def simplify(weights: NDArray[np.floating], cells: NDArray[np.integer]) -> NDArray[np.intp]:
    """Indices of the path cells kept as waypoints: a straight segment replaces a run of cells when
    it crosses no cell heavier than the heaviest cell of that run (so it never cuts through
    unknown space the search avoided)."""
    if len(cells) <= 2:
        return np.arange(len(cells), dtype=np.intp)
    w = _grid(np.asarray(weights))
    return _simplify(w, np.ascontiguousarray(cells, dtype=np.int64)).astype(np.intp)


def expanded(weights: NDArray[np.floating]) -> int:
    """Cells expanded by the last search on ``weights`` (for benchmarks: expansions per second)."""
    with _WORK_LOCK:
        have = _WORK.get(id(weights))
    if have is None or have[0]() is not weights or have[1].gen == 0:
        return 0
    return int(np.count_nonzero(have[1].stamp == np.uint8(have[1].gen + 1)))
