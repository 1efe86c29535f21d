"""The cheapest cells of a target set from a start, one at a time, without searching the whole grid.

Goal selection wants the cheapest cell near an object that also passes a test too costly to run
on every candidate up front (a line of sight). ``NearestSearch`` is an A* towards the box that
holds the candidates (the octile distance to the box, times the smallest weight, is admissible
and consistent, and zero on every candidate), so candidates come out in increasing path cost; it
pauses at each candidate it settles and resumes from there when the caller rejects it. A
selection that accepts the first candidate it meets expands only the cells cheaper than it,
and those towards the object; exhausting the set costs one whole-grid Dijkstra, as before.

Moves and costs are those of :mod:`capnav.planning.search` (8-connected, the mean of the two
weights times the step length). Those costs are the same both ways, so a walk from a set of cells
gives every cell's cost *to* them (:func:`goal_field`): with it as the heuristic the search
follows the cheapest path to the set and expands little more than that path.
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
    UNSEEN,
    _grid,
    _grow,
    _min_finite,
    _pop,
    _push,
)

#: A cell of a goal field from which no target is reachable.
NO_PATH = 65535
#: A goal field's unit: 1/32 of a cell's cost (a uint16 holds costs up to 2048 cells; larger ones
#: are stored as 2048, still a lower bound).
FIELD_UNIT = 1.0 / 32.0


@njit(cache=True, nogil=True)
def _resume(w: NDArray[np.floating], g: NDArray[np.float64], state: NDArray[np.uint8], hf: NDArray[np.float64],
            hi: NDArray[np.int64], size: int, target: NDArray[np.bool_], box: NDArray[np.int64], hscale: float,
            hq: NDArray[np.uint16], hunit: float) -> tuple[int, int, NDArray[np.float64], NDArray[np.int64]]:
    """Run until a target cell is settled (returned after expanding it) or the heap is empty (-1).
    ``target`` covers ``box`` only (its rows, cols): the cells outside it are never targets.

    ``hq`` (empty: the octile distance to the box, times ``hscale``) is a lower bound of every
    cell's cost to the targets in units of ``hunit`` (``NO_PATH``: none reachable, the cell is
    not entered). Rounded down, it may be inconsistent by one unit, so a settled cell is opened
    again when a cheaper way to it turns up: the first target settled is still the cheapest."""
    rows, cols = w.shape
    field = hq.shape[0] > 0
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
            if sv == CLOSED and not field:
                continue
            ng = gu + _STEP[k] * 0.5 * (wu + wv)
            if ng < (g[v] if sv != UNSEEN else np.inf):
                if field:
                    hv = hq[v]
                    if hv == NO_PATH:
                        continue
                    h = hunit * hv
                else:
                    # The octile distance to the box, inline.
                    dr = max(r0 - vr, 0, vr - r1)
                    dc = max(c0 - vc, 0, vc - c1)
                    h = hscale * ((SQRT2 - 1.0) * min(dr, dc) + max(dr, dc))
                g[v] = ng
                state[v] = OPEN
                if size == hf.shape[0]:
                    hf, hi = _grow(hf, hi)
                _push(hf, hi, size, ng + h, v)
                size += 1
        if r0 <= ur <= r1 and c0 <= uc <= c1 and target[(ur - r0) * bw + uc - c0]:
            return u, size, hf, hi
    return -1, size, hf, hi


class NearestSearch:
    """Settle the cells of ``target`` (bool, the grid's shape or the shape of ``box`` = (r0, c0, r1,
    c1) inclusive, all of its cells inside the box) in increasing path cost from ``start`` on
    ``weights``; ``next()`` gives the next one. ``min_weight`` (the smallest finite weight) saves a
    scan of the grid when the caller knows it; 0 searches without a heuristic (a Dijkstra).

    ``start`` may be several cells ((K, 2) rows, cols: a search from the nearest of them).
    ``field`` (uint16, one per cell of the grid, from :func:`goal_field`) replaces the octile
    distance to the box as the heuristic: a lower bound of each cell's cost to the targets, so
    the search heads for the cheapest target along its path instead of spreading towards the box."""

    def __init__(self, weights: NDArray[np.floating], start: tuple[int, int] | NDArray[np.integer],
                 target: NDArray[np.bool_], box: tuple[int, int, int, int], min_weight: float | None = None,
                 field: NDArray[np.uint16] | None = None) -> None:
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
        if field is not None and field.shape != (n,):
            raise ValueError(f"field must hold one value per cell ({n}), got shape {field.shape}")
        self.hq = np.zeros(0, np.uint16) if field is None else field
        self.hunit = FIELD_UNIT * (1.0 + TIE_BREAK)
        starts = np.asarray(start, dtype=np.int64).reshape(-1, 2)
        flat = np.unique(starts[:, 0] * cols + starts[:, 1])
        self.hf = np.empty(max(4096, 2 * len(flat)), np.float64)
        self.hi = np.empty(len(self.hf), np.int64)
        self.g[flat] = 0.0
        self.state[flat] = OPEN
        self.hf[:len(flat)] = 0.0  # equal keys: any order is a heap
        self.hi[:len(flat)] = flat
        self.size = len(flat)
        self.exhausted = False

    def next(self) -> tuple[tuple[int, int], float] | None:
        """The next cheapest target cell and its cost (in cells), or None when none is left."""
        if self.exhausted:
            return None
        u, self.size, self.hf, self.hi = _resume(self.w, self.g, self.state, self.hf, self.hi, self.size,
                                                 self.target, self.box, self.hscale, self.hq, self.hunit)
        if u < 0:
            self.exhausted = True
            return None
        return (u // self.cols, u % self.cols), float(self.g[u])

    def finish(self) -> NDArray[np.float64]:
        """Search on to the end; the cost (rows, cols) of every settled cell, inf elsewhere."""
        none = np.zeros_like(self.target)  # no target: on to the end
        if not self.exhausted:
            _resume(self.w, self.g, self.state, self.hf, self.hi, self.size, none, self.box, self.hscale, self.hq,
                    self.hunit)
            self.exhausted = True
        out = np.where(self.state == CLOSED, self.g, np.inf)
        return out.reshape(self.w.shape)


def padded_weights(w: NDArray[np.floating]) -> NDArray[np.floating]:
    """``w`` flattened on a grid padded by a one-cell border of inf (no bounds checks in
    :func:`_cost_walk`), in ``w``'s own dtype: a move then costs the very float the search adds."""
    w = _grid(np.asarray(w))
    return np.pad(w, 1, constant_values=np.inf).ravel()


@njit(cache=True, nogil=True)
def _cost_walk(wp: NDArray[np.floating], cols: int, seeds: NDArray[np.int64], width: float, nb: int
               ) -> NDArray[np.float64]:
    """Path costs (the moves of :mod:`capnav.planning.search`) from the nearest seed to every
    cell of the padded weights ``wp``, by buckets of ``width`` (at most the cheapest move, so a
    cell's cost is final once the buckets below its own are done: Dinitz's observation, as in
    :mod:`capnav.core.geodesic`) kept in ``nb`` rotating lists (more than the dearest move spans):
    a few array reads per cell, no heap."""
    w = cols + 2
    n = wp.shape[0]
    dist = np.full(n, np.inf)
    lists = np.empty((nb, n + seeds.shape[0]), np.int32)
    fill = np.zeros(nb, np.int64)
    offs = np.array([-w - 1, -w, -w + 1, -1, 1, w - 1, w, w + 1], np.int64)
    steps = np.array([SQRT2, 1.0, SQRT2, 1.0, 1.0, SQRT2, 1.0, SQRT2])
    for i in range(seeds.shape[0]):
        u = (seeds[i, 0] + 1) * w + seeds[i, 1] + 1
        if dist[u] != 0.0:
            dist[u] = 0.0
            lists[0, fill[0]] = u
            fill[0] += 1
    pending = fill[0]
    k = 0
    while pending > 0:
        slot = k % nb
        j = 0
        while j < fill[slot]:  # a bucket is not added to while it is expanded (moves >= width)
            u = lists[slot, j]
            j += 1
            du = dist[u]
            if int(du / width) < k:  # expanded from an earlier bucket (the push's own rounding)
                continue
            wu = wp[u]
            for m in range(8):
                v = u + offs[m]
                wv = wp[v]
                if not wv < np.inf:
                    continue
                nd = du + steps[m] * 0.5 * (wu + wv)
                dv = dist[v]
                if nd < dv:
                    b = int(nd / width)
                    if dv == np.inf or int(dv / width) != b:
                        t = b % nb
                        lists[t, fill[t]] = v
                        fill[t] += 1
                        pending += 1
                    dist[v] = nd
        pending -= fill[slot]
        fill[slot] = 0
        k += 1
    return dist


def goal_field(weights: NDArray[np.floating], sources: NDArray[np.integer], min_weight: float,
               padded: NDArray[np.floating] | None = None) -> NDArray[np.uint16]:
    """A lower bound of the cost from every cell to the nearest of ``sources`` ((K, 2) rows, cols)
    as a heuristic for :class:`NearestSearch` (flat, uint16 in ``FIELD_UNIT``, rounded down;
    ``NO_PATH`` where none is reachable): the path cost from the sources (moves cost the same both
    ways, the mean of the two weights times the step), by a bucket walk instead of a heap.
    ``padded``: :func:`padded_weights` of ``weights``, kept by the caller."""
    w = _grid(np.asarray(weights))
    rows, cols = w.shape
    if padded is None:
        padded = padded_weights(w)
    finite = padded[np.isfinite(padded)]
    width = max(float(min_weight), 1e-6)
    dearest = SQRT2 * float(finite.max()) if finite.size else 1.0
    d = _cost_walk(padded, cols, np.asarray(sources, dtype=np.int64).reshape(-1, 2), width,
                   int(np.ceil(dearest / width)) + 2)
    d = d.reshape(rows + 2, cols + 2)[1:-1, 1:-1].ravel()
    out = np.full(d.shape, NO_PATH, np.uint16)
    ok = np.isfinite(d)
    # A hair below the cost, so that rounding never lifts the bound above the cost a search adds
    # up (the same moves, summed in the other order).
    out[ok] = np.minimum(np.floor(d[ok] * ((1.0 - 1e-12) / FIELD_UNIT)), NO_PATH - 1).astype(np.uint16)
    return out
