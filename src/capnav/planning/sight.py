"""Lines of sight on the planner's occupancy grid: which standing cells see an object's footprint.

Goal selection prefers a standing cell from which the object is in view, so the agent does not
stop 0.7 m from a lamp with the lamp's wall between them. The planner knows only its mapped grid,
so sight is traced there (the evaluation's strict rule traces the true floor plan, in ``sim/``):

- OCCUPIED cells block, except the object's own cells: those whose centre lies within half a cell
  of the footprint (they overlap or touch it; the mapped hull and the object's occupied cells
  disagree by up to a cell). A wall flush with the object keeps its farther cell layers, so sight
  through a 0.1 m wall still fails on a 0.05 m grid.
- UNKNOWN cells do not block. The object was seen, so the walls around it are mapped from its
  side; unknown cells within reach are mostly occlusion shadows and unobserved floor, and the
  planner already drives through unknown space (``unknown_cost``). Blocking them would drop the
  preference on sparse maps, where nearly every line crosses some unknown cell.
- Low furniture is occupied on the map, so it blocks here although a camera sees over it: the
  test is conservative, and when no cell passes it, goal selection falls back to distance alone.

A line runs from the candidate cell's centre to a target cell's centre with the exact grid
traversal of :func:`capnav.planning.search.line_clear`; targets are the rim cells of the footprint
(at most ``MAX_TARGETS``, evenly spread) and the centroid's cell.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from capnav.core.footprint import footprint_distance
from capnav.core.grid import OCCUPIED, OccupancyGrid
from capnav.planning.search import line_clear

#: Most footprint cells a candidate is tested against (a rim of a 2 m bed has ~160 cells at 0.05 m).
MAX_TARGETS = 48


@njit(cache=True)
def _sees(w: NDArray[np.float64], cands: NDArray[np.int64], targets: NDArray[np.int64]) -> NDArray[np.bool_]:
    out = np.zeros(cands.shape[0], np.bool_)
    for i in range(cands.shape[0]):
        for j in range(targets.shape[0]):
            if line_clear(w, cands[i, 0], cands[i, 1], targets[j, 0], targets[j, 1], 0.5):
                out[i] = True
                break
    return out


def sees_footprint(occ: OccupancyGrid, footprint: NDArray[np.float64], cells: NDArray[np.integer],
                   centroid: NDArray[np.float64]) -> NDArray[np.bool_]:
    """For each of ``cells`` (N, 2) row, col, whether a straight line from its centre reaches the
    footprint (K, 2) without crossing an occupied cell (see the module notes for what blocks).

    Works on the window spanning the cells and the footprint only, so its cost grows with the
    number of candidates, not with the map."""
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if len(cells) == 0:
        return np.zeros(0, dtype=bool)
    spec = occ.spec
    fp_rc = spec.to_cell(np.vstack([footprint, centroid[None, :]]))
    lo = np.maximum(np.minimum(cells.min(axis=0), fp_rc.min(axis=0)), 0)
    hi = np.minimum(np.maximum(cells.max(axis=0), fp_rc.max(axis=0)), [spec.rows - 1, spec.cols - 1])
    window = occ.cells[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1]
    own = np.zeros(window.shape, dtype=bool)
    # The object's own cells lie in its box grown by half a cell: measure only those.
    half = 0.5 * spec.resolution
    a = np.maximum(spec.to_cell(footprint.min(axis=0) - half), lo)
    b = np.minimum(spec.to_cell(footprint.max(axis=0) + half), hi)
    if (a <= b).all():
        rr, cc = np.mgrid[a[0]:b[0] + 1, a[1]:b[1] + 1]
        centres = spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
        own[rr - lo[0], cc - lo[1]] = (footprint_distance(centres, footprint) <= half + 1e-9).reshape(rr.shape)
    w = np.where((window == OCCUPIED) & ~own, np.inf, 0.0)
    targets = _targets(own, spec.to_cell(centroid) - lo, w.shape)
    return _sees(np.ascontiguousarray(w), np.ascontiguousarray(cells - lo), targets)


def _targets(own: NDArray[np.bool_], centroid_rc: NDArray[np.intp], shape: tuple[int, ...]) -> NDArray[np.int64]:
    """The rim of the object's cells (cells with a 4-neighbour outside), evenly thinned, plus the
    centroid's cell (the only target of a footprint too thin to cover a cell centre)."""
    pad = np.pad(own, 1)
    inner = pad[:-2, 1:-1] & pad[2:, 1:-1] & pad[1:-1, :-2] & pad[1:-1, 2:]
    rim = np.argwhere(own & ~inner)
    if len(rim) > MAX_TARGETS:
        rim = rim[np.linspace(0, len(rim) - 1, MAX_TARGETS).round().astype(np.intp)]
    c = np.clip(centroid_rc, 0, np.asarray(shape) - 1)
    return np.ascontiguousarray(np.vstack([rim, c[None, :]]), dtype=np.int64)
