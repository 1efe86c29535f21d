"""Geodesic distances on the top-down map, so that room cues do not leak through walls.

A cue object (a stove, a bed) says "kitchen" or "bedroom" to the objects it can be walked to in a
few metres, not to those behind a wall. Distances are computed through free space and furniture
(a sofa does not cut a room in two), never through walls: occupied cells that no object's box
covers. The grid's one-cell unsampled gaps are closed first (``fill_gaps``).

Rooms (``room_regions``) must not hang on one row of cells: a pocket of free space behind
furniture whose only way out is a strip no frame saw (a component of the walkable domain of its
own) takes the room it opens into through the unseen cells, and an object's room is voted only
by cells joined to its own (``object_region``), never by the next room's beyond a wall.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid


def fill_gaps(cells: NDArray[np.uint8], passes: int = 2) -> NDArray[np.uint8]:
    """Close one-cell UNKNOWN gaps whose two opposite neighbours agree (left/right or up/down).

    A grid finer than the voxels it was built from leaves such unsampled lines; left open they
    open holes in walls."""
    c = cells.copy()
    for _ in range(passes):
        unk = c == UNKNOWN
        if not unk.any():
            break
        pad = np.pad(c, 1, constant_values=UNKNOWN)
        left, right = pad[1:-1, :-2], pad[1:-1, 2:]
        down, up = pad[:-2, 1:-1], pad[2:, 1:-1]
        h = unk & (left == right) & (left != UNKNOWN)
        v = unk & ~h & (down == up) & (down != UNKNOWN)
        c[h] = left[h]
        c[v] = down[v]
    return c


def box_cells(spec: GridSpec, lo: NDArray[np.floating], hi: NDArray[np.floating],
              shrink: int = 0) -> tuple[int, int, int, int]:
    """Inclusive (r0, c0, r1, c1) cell range of a world box, clipped to the grid (may be empty)."""
    r0, c0 = spec.to_cell(np.asarray(lo, dtype=np.float64))
    r1, c1 = spec.to_cell(np.asarray(hi, dtype=np.float64))
    return (max(int(r0) + shrink, 0), max(int(c0) + shrink, 0),
            min(int(r1) - shrink, spec.rows - 1), min(int(c1) - shrink, spec.cols - 1))


def walkable_domain(occ: OccupancyGrid, boxes_lo: NDArray[np.float64], boxes_hi: NDArray[np.float64]
                    ) -> NDArray[np.bool_]:
    """Free cells plus the cells of object boxes (an object's own surface must not wall it in)."""
    cells = fill_gaps(occ.cells)
    dom = cells == FREE
    occupied = cells == OCCUPIED
    for lo, hi in zip(boxes_lo, boxes_hi, strict=True):
        r0, c0, r1, c1 = box_cells(occ.spec, lo, hi)
        if r1 >= r0 and c1 >= c0:
            dom[r0:r1 + 1, c0:c1 + 1] |= occupied[r0:r1 + 1, c0:c1 + 1]
    return dom


def unseen_cells(occ: OccupancyGrid) -> NDArray[np.bool_]:
    """Cells no frame saw (after ``fill_gaps``): not walkable, but no wall either."""
    return fill_gaps(occ.cells) == UNKNOWN


def room_regions(occ: OccupancyGrid, boxes_lo: NDArray[np.float64], boxes_hi: NDArray[np.float64],
                 door_width: float = 1.0, min_core_m2: float = 1.0) -> NDArray[np.int32]:
    """``segment_rooms`` of the walkable domain, pockets reached through unseen cells included."""
    return segment_rooms(walkable_domain(occ, boxes_lo, boxes_hi), occ.spec, door_width, min_core_m2,
                         unseen=unseen_cells(occ))


def box_seeds(domain: NDArray[np.bool_], spec: GridSpec, los: NDArray[np.floating], his: NDArray[np.floating]
              ) -> NDArray[np.int64]:
    """The walkable cells (K, 2) row, col of several boxes: where a walk from them starts."""
    seeds_list = []
    for lo, hi in zip(np.atleast_2d(los), np.atleast_2d(his), strict=True):
        r0, c0, r1, c1 = box_cells(spec, lo, hi)
        if r1 < r0 or c1 < c0:
            continue
        rr, cc = np.mgrid[r0:r1 + 1, c0:c1 + 1]
        seeds_list.append(np.stack([rr.ravel(), cc.ravel()], axis=1))
    if not seeds_list:
        return np.empty((0, 2), np.int64)
    seeds = np.concatenate(seeds_list).astype(np.int64)
    return seeds[domain[seeds[:, 0], seeds[:, 1]]]


def geodesic_from_boxes(domain: NDArray[np.bool_], spec: GridSpec, los: NDArray[np.floating],
                        his: NDArray[np.floating], limit_m: float = 12.0) -> NDArray[np.float64]:
    """Metres from the nearest of several boxes to every cell through ``domain`` (inf where
    unreachable or beyond ``limit_m``): one multi-source Dijkstra."""
    seeds = box_seeds(domain, spec, los, his)
    if len(seeds) == 0:
        return np.full(domain.shape, np.inf)
    from capnav.core.geodesic import grid_geodesic  # numba only when a distance is asked for

    return grid_geodesic(domain, seeds, limit_m / spec.resolution) * spec.resolution


def box_min(field: NDArray[np.float64], spec: GridSpec, lo: NDArray[np.floating], hi: NDArray[np.floating],
            ring: float = 0.3) -> float:
    """Smallest value of ``field`` over a box's cells (grown by ``ring`` m when all are inf)."""
    for grow in (0.0, ring):
        r0, c0, r1, c1 = box_cells(spec, np.asarray(lo) - grow, np.asarray(hi) + grow)
        if r1 >= r0 and c1 >= c0:
            v = float(field[r0:r1 + 1, c0:c1 + 1].min())
            if np.isfinite(v):
                return v + grow
    return float("inf")


def segment_rooms(domain: NDArray[np.bool_], spec: GridSpec, door_width: float = 1.0,
                  min_core_m2: float = 1.0, unseen: NDArray[np.bool_] | None = None) -> NDArray[np.int32]:
    """Rooms as regions of the walkable domain: label per cell (-1 outside the domain).

    Interior doors are narrower than ``door_width``: eroding the domain by half of it closes every
    doorway (and any leak through a box that pokes through a wall), so each room's interior is one
    connected core. Cores smaller than ``min_core_m2`` are dropped; every other domain cell then
    goes to the core it is walked to first (one geodesic per core), so a doorway, a corridor too
    narrow for a core and the space under furniture belong to the room they open into.

    ``unseen`` (cells no frame saw): domain cells no core reaches (a pocket behind a sofa whose
    way out nobody saw) go to the labelled cells they are walked to first through the domain and
    the unseen cells, never through a wall, so a pocket takes the room it opens into. Without
    it they stay -1 and an object standing there is given whatever room lies across the wall."""
    from capnav.core.geodesic import grid_geodesic  # numba only when rooms are segmented

    r = int(np.ceil(0.5 * door_width / spec.resolution))
    yy, xx = np.mgrid[-r:r + 1, -r:r + 1]
    core = ndimage.binary_erosion(domain, structure=(xx**2 + yy**2) <= r * r, border_value=0)
    lab, n = ndimage.label(core)
    labels = np.full(domain.shape, -1, dtype=np.int32)
    if n == 0:
        return labels
    sizes = ndimage.sum_labels(core, lab, index=np.arange(1, n + 1)) * spec.resolution**2
    best = np.full(domain.shape, np.inf)
    k = 0
    for j in np.flatnonzero(sizes >= min_core_m2):
        rr, cc = np.nonzero(lab == j + 1)
        d = grid_geodesic(domain, np.stack([rr, cc], axis=1).astype(np.int64), np.inf)
        closer = d < best
        labels[closer] = k
        best[closer] = d[closer]
        k += 1
    pocket = domain & (labels < 0)
    if unseen is not None and k > 0 and pocket.any():
        through = domain | unseen
        best = np.full(domain.shape, np.inf)
        found = np.full(domain.shape, -1, dtype=np.int32)
        for room in range(k):
            rr, cc = np.nonzero(labels == room)
            d = grid_geodesic(through, np.stack([rr, cc], axis=1).astype(np.int64), np.inf)
            closer = pocket & (d < best)
            found[closer] = room
            best[closer] = d[closer]
        labels[pocket] = found[pocket]
    return labels


def object_region(labels: NDArray[np.int32], spec: GridSpec, lo: NDArray[np.floating], hi: NDArray[np.floating],
                  ring: float = 0.3) -> int:
    """The room region an object is reached from: the most frequent label of the walkable cells
    in a ring around its box (the inner half of the box counts too), -1 when none."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    r0, c0, r1, c1 = box_cells(spec, lo - ring, hi + ring)
    if r1 < r0 or c1 < c0:
        return -1
    patch = labels[r0:r1 + 1, c0:c1 + 1]
    q = 0.25 * (hi - lo)
    i0, j0, i1, j1 = box_cells(spec, lo + q, hi - q)
    weights = np.ones(patch.shape)
    b0, b1, d0, d1 = max(i0 - r0, 0), max(i1 - r0 + 1, 0), max(j0 - c0, 0), max(j1 - c0 + 1, 0)
    # Cells under the box's outer rim may lie beyond the wall it stands against: they do not vote.
    fr0, fc0, fr1, fc1 = box_cells(spec, lo, hi)
    weights[max(fr0 - r0, 0):max(fr1 - r0 + 1, 0), max(fc0 - c0, 0):max(fc1 - c0 + 1, 0)] = 0.0
    weights[b0:b1, d0:d1] = 1.0
    valid = patch >= 0
    if not valid.any():
        return -1
    # Only cells joined to the object's own (its inner half's, else its box's) through labelled
    # cells of the ring vote: the next room's, beyond a wall (-1 cells), do not.
    joined = valid
    comp, _ = ndimage.label(valid)
    for own in ((slice(b0, b1), slice(d0, d1)),
                (slice(max(fr0 - r0, 0), max(fr1 - r0 + 1, 0)), slice(max(fc0 - c0, 0), max(fc1 - c0 + 1, 0)))):
        ids = np.unique(comp[own])
        ids = ids[ids > 0]
        if len(ids):
            mine = np.isin(comp, ids)
            if (weights[mine] > 0).any():
                joined = mine
                break
    votes = np.bincount(patch[joined], weights=weights[joined])
    return int(np.argmax(votes)) if votes.max() > 0 else -1
