"""Frontiers: known-free cells that touch unknown space, clustered into goals for exploration.

Frontier cells are clustered with 8-connectivity and cut into tiles; each cluster is summarised
by one reachable target cell (the reachable cell nearest to the cluster's centroid) and its path
cost from the agent, read from a cost field computed once per decision for all clusters.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.grid import FREE, UNKNOWN, OccupancyGrid

_EIGHT = np.ones((3, 3), bool)


@dataclass(frozen=True)
class Frontier:
    """One frontier cluster: where to go (``target_xy``), how big it is and how far by path."""

    target_rc: tuple[int, int]
    target_xy: tuple[float, float]
    centroid_xy: tuple[float, float]
    size: int  # cells
    path_distance: float  # metres from the agent through traversable cells (inf if unreachable)


def find_frontiers(grid: OccupancyGrid, dist: NDArray[np.float64], min_cells: int = 4,
                   max_extent: float = 1.5) -> list[Frontier]:
    """Frontier clusters of ``grid`` with at least ``min_cells`` cells, nearest (by path) first.

    ``dist`` is the path cost (m) from the agent to every cell, inf where the agent cannot stand.

    Connected frontier cells are cut into tiles of ``max_extent`` metres: the free space seen
    from one spot is ringed by a single long frontier, whose centroid would be useless as a goal.

    A cluster whose cells are all unreachable (``dist`` inf) keeps ``path_distance`` inf and its
    target is the cell nearest its centroid, so callers can still see it but should not pick it.
    """
    free = grid.cells == FREE
    unknown = grid.cells == UNKNOWN
    near_unknown = ndimage.binary_dilation(unknown, structure=np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], bool))
    front = free & near_unknown
    labels, n = ndimage.label(front, structure=_EIGHT)
    if n == 0:
        return []
    rr, cc = np.nonzero(labels)
    tile = max(1, round(max_extent / grid.spec.resolution))
    tiles_per_row = grid.spec.cols // tile + 1
    key = (labels[rr, cc].astype(np.int64) * (grid.spec.rows // tile + 1) + rr // tile) * tiles_per_row + cc // tile
    _, lab = np.unique(key, return_inverse=True)
    lab = lab.reshape(-1)
    n = int(lab.max()) + 1
    sizes = np.bincount(lab, minlength=n)
    cy = np.bincount(lab, weights=rr, minlength=n) / np.maximum(sizes, 1)
    cx = np.bincount(lab, weights=cc, minlength=n) / np.maximum(sizes, 1)
    # Reachable cells of a cluster: the frontier cell itself, or a passable cell right next to it
    # (frontier cells hug walls, where the inflated obstacle makes them impassable).
    d_cell = dist[rr, cc]
    reach_d = _nearest_reachable(dist, rr, cc)
    spec = grid.spec
    out: list[Frontier] = []
    for k in range(n):
        if sizes[k] < min_cells:
            continue
        members = np.flatnonzero(lab == k)
        dcent = (rr[members] - cy[k]) ** 2 + (cc[members] - cx[k]) ** 2
        best_d = reach_d[0][members]
        reachable = np.isfinite(best_d)
        if reachable.any():
            # Among reachable members, the one nearest the centroid (ties: shorter path).
            order = np.lexsort((best_d[reachable], dcent[reachable]))
            m = members[reachable][order[0]]
            tr, tc = int(reach_d[1][m]), int(reach_d[2][m])
            pd = float(best_d[reachable][order[0]])
        else:
            m = members[int(np.argmin(dcent))]
            tr, tc, pd = int(rr[m]), int(cc[m]), float(d_cell[m])
        txy = spec.to_world(np.array([tr, tc]))
        cxy = spec.to_world(np.array([cy[k], cx[k]]))
        out.append(Frontier((tr, tc), (float(txy[0]), float(txy[1])), (float(cxy[0]), float(cxy[1])),
                            int(sizes[k]), pd))
    out.sort(key=lambda f: f.path_distance)
    return out


def _nearest_reachable(dist: NDArray[np.float64], rr: NDArray[np.intp],
                       cc: NDArray[np.intp], reach: int = 6) -> tuple[NDArray[np.float64], NDArray[np.intp],
                                                                      NDArray[np.intp]]:
    """For each cell (rr, cc): the reachable cell within ``reach`` cells (Chebyshev) of smallest path
    distance, as (distance, row, col). Vectorised over the window offsets."""
    rows, cols = dist.shape
    best = np.full(len(rr), np.inf)
    br = rr.astype(np.intp).copy()
    bc = cc.astype(np.intp).copy()
    for dr in range(-reach, reach + 1):
        for dc in range(-reach, reach + 1):
            r2, c2 = rr + dr, cc + dc
            ok = (r2 >= 0) & (r2 < rows) & (c2 >= 0) & (c2 < cols)
            d = np.full(len(rr), np.inf)
            d[ok] = dist[r2[ok], c2[ok]]
            better = d < best
            best[better] = d[better]
            br[better] = r2[better]
            bc[better] = c2[better]
    return best, br, bc
