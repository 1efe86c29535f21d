"""Ground-truth navigability: where the agent's centre fits, geodesic distances and shortest paths."""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.sim.shapes import RectSet

CLEARANCE_CAP = 2.0  # clearances (distance to the nearest obstacle) are exact up to this (m)
_NEIGHBOURS = ((0, 1, 1.0), (1, 0, 1.0), (1, 1, np.sqrt(2.0)), (1, -1, np.sqrt(2.0)))


class NavGrid:
    """Navigable cells (agent disk clear of every obstacle, in the main connected region) and
    geodesic distances on them (8-connected, no corner cutting)."""

    def __init__(self, obstacles: RectSet, bounds: tuple[float, float, float, float], radius: float,
                 resolution: float) -> None:
        xmin, ymin, xmax, ymax = bounds
        self.spec = GridSpec.covering(xmin, ymin, xmax, ymax, resolution, margin=2 * resolution)
        rr, cc = np.mgrid[0:self.spec.rows, 0:self.spec.cols]
        centres = self.spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
        inside = ((centres[:, 0] > xmin) & (centres[:, 0] < xmax) & (centres[:, 1] > ymin)
                  & (centres[:, 1] < ymax)).reshape(rr.shape)
        s = self.spec
        self.clearance = obstacles.distance_grid(s.x0, s.y0, s.resolution, s.rows, s.cols, cap=CLEARANCE_CAP)
        self.inside = inside
        fits = inside & (self.clearance > radius)
        labels, n = ndimage.label(fits, structure=np.ones((3, 3), dtype=bool))
        if n == 0:
            self.free = fits
        else:
            sizes = ndimage.sum_labels(np.ones_like(labels), labels, index=np.arange(1, n + 1))
            self.free = labels == (int(np.argmax(sizes)) + 1)
        self.radius = radius
        self._graph: csr_matrix | None = None
        self._node = np.full(self.free.shape, -1, dtype=np.int64)
        self._node[self.free] = np.arange(int(self.free.sum()))
        self._cells = np.argwhere(self.free)
        self._fields: OrderedDict[int, NDArray[np.float64]] = OrderedDict()
        self._preds: OrderedDict[int, NDArray[np.int32]] = OrderedDict()

    # -- grids -----------------------------------------------------------------------------
    def navigable(self) -> OccupancyGrid:
        cells = np.where(self.free, FREE, OCCUPIED).astype(np.uint8)
        return OccupancyGrid(self.spec, cells)

    def obstacles(self) -> OccupancyGrid:
        """Obstacle footprints: a cell is OCCUPIED when it overlaps an obstacle, UNKNOWN outside."""
        occ = self.clearance <= self.spec.resolution / 2
        cells = np.where(occ, OCCUPIED, FREE).astype(np.uint8)
        cells[~self.inside & ~occ] = UNKNOWN
        return OccupancyGrid(self.spec, cells)

    # -- graph -----------------------------------------------------------------------------
    def _build_graph(self) -> csr_matrix:
        R, C = self.free.shape
        r0, c0 = self._cells[:, 0], self._cells[:, 1]
        rows, cols, w = [], [], []
        for dr, dc, cost in _NEIGHBOURS:
            r1, c1 = r0 + dr, c0 + dc
            ok = (r1 < R) & (c1 >= 0) & (c1 < C)
            ok[ok] = self.free[r1[ok], c1[ok]]
            if dr and dc:  # diagonal: both orthogonal neighbours must be free (no corner cutting)
                ok[ok] &= self.free[r1[ok], c0[ok]] & self.free[r0[ok], c1[ok]]
            ia, ib = self._node[r0[ok], c0[ok]], self._node[r1[ok], c1[ok]]
            rows += [ia, ib]
            cols += [ib, ia]
            w += [np.full(ia.size, cost * self.spec.resolution)] * 2
        n = len(self._cells)
        return csr_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))

    @property
    def graph(self) -> csr_matrix:
        if self._graph is None:
            self._graph = self._build_graph()
        return self._graph

    def snap(self, xy: tuple[float, float], max_dist: float) -> tuple[int, float]:
        """Node of the navigable cell nearest to ``xy`` (-1 if none within ``max_dist``), and its distance."""
        if len(self._cells) == 0:
            return -1, np.inf
        rc = self.spec.to_cell(np.asarray(xy, dtype=np.float64))
        if bool(self.spec.inside(rc)) and self.free[rc[0], rc[1]]:
            return int(self._node[rc[0], rc[1]]), 0.0
        centres = self.spec.to_world(self._cells)
        d = np.hypot(centres[:, 0] - xy[0], centres[:, 1] - xy[1])
        k = int(np.argmin(d))
        return (k, float(d[k])) if d[k] <= max_dist else (-1, np.inf)

    def distance_field(self, node: int) -> tuple[NDArray[np.float64], NDArray[np.int32]]:
        """Geodesic distances and predecessors from ``node`` to every navigable node (cached)."""
        if node not in self._fields:
            dist, pred = dijkstra(self.graph, directed=False, indices=node, return_predecessors=True)
            self._fields[node], self._preds[node] = dist, pred
            if len(self._fields) > 16:
                self._fields.popitem(last=False)
                self._preds.popitem(last=False)
        return self._fields[node], self._preds[node]

    def geodesic(self, start: tuple[float, float], goal: tuple[float, float], snap: float) -> float:
        s, ds = self.snap(start, snap)
        g, dg = self.snap(goal, snap)
        if s < 0 or g < 0:
            return float("inf")
        dist, _ = self.distance_field(g)
        return float(dist[s] + ds + dg)

    def path(self, start: tuple[float, float], goal: tuple[float, float], snap: float) -> NDArray[np.float64]:
        """World (K, 2) cell centres of a shortest path start -> goal (empty if unreachable)."""
        s, _ = self.snap(start, snap)
        g, _ = self.snap(goal, snap)
        if s < 0 or g < 0:
            return np.zeros((0, 2))
        dist, pred = self.distance_field(g)
        if not np.isfinite(dist[s]):
            return np.zeros((0, 2))
        nodes = [s]
        while nodes[-1] != g:
            nodes.append(int(pred[nodes[-1]]))
        return self.spec.to_world(self._cells[nodes])

    def free_points(self) -> NDArray[np.float64]:
        return self.spec.to_world(self._cells)


def start_cells(clearance: NDArray[np.floating], inside: NDArray[np.bool_], margin: float) -> NDArray[np.bool_]:
    """Where an episode may start: cells whose clearance to every true obstacle exceeds ``margin``
    (the planner's inflation and a map cell: the start is free on the robot's own costmap, not
    only on the true grid), in the largest region connected through such cells (so the way out of
    the start has the margin too, not just the robot's radius)."""
    fits = np.asarray(inside, dtype=bool) & (np.asarray(clearance) > margin)
    labels, n = ndimage.label(fits, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        return fits
    sizes = ndimage.sum_labels(np.ones_like(labels), labels, index=np.arange(1, n + 1))
    return np.asarray(labels == int(np.argmax(sizes)) + 1)
