"""Lines of sight from a standing robot's eye to an object, traced in 3D through the mapped voxels.

A person who is sent to a TV on the wall stops where they see it, and a cabinet under the TV
does not hide it from eye height. The planner's 2D occupancy cannot say that (the cabinet's cells
are occupied at every height there), so sight is traced through :class:`HeightColumns`: per grid
cell, a 64-bit mask of the height bins (voxel size, from the floor) where the map holds an
observed surface. A ray from the eye (``eye_height`` above the candidate cell's centre) to a point
of the object crosses a cell at the heights the segment spans there; it is blocked when one of
those bins is set.

- The object's own cells (centres within half a cell of its footprint) are cleared only in its
  own height range: the cabinet under the TV still blocks a ray aimed below the TV.
- Occupied cells of the planning grid with no voxel column (contact marks, grids built without
  voxels) block at every height, so without voxels the test is the 2D one: every occupied cell
  blocks, low furniture included (conservative: goal selection then falls back, and says so).
- UNKNOWN cells do not block: the object was seen, so the walls around it are mapped from its
  side; unknown cells near it are occlusion shadows and unobserved floor.

A ray runs from the candidate cell's centre to a target cell's centre with an exact grid traversal
(Amanatides-Woo, as :func:`capnav.planning.search.line_clear`); targets are the rim cells of the
footprint (at most ``MAX_TARGETS``, evenly spread) and the centroid's cell, each at two heights
of the object (the middle and near the top of its box).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from capnav.core.grid import OCCUPIED, GridSpec, OccupancyGrid
from capnav.planning.polygon import polygon_distance

#: Most footprint cells a candidate is tested against (a rim of a 2 m bed has ~160 cells at 0.05 m).
MAX_TARGETS = 32
#: Height bins per column (64 bins of 0.05 m reach 3.2 m, above every ceiling the simulator builds).
BINS = 64
ALL = np.uint64(0xFFFFFFFFFFFFFFFF)


@dataclass(frozen=True)
class HeightColumns:
    """``masks`` (rows, cols) uint64 on ``spec``: bit k set when an observed surface lies between
    ``k * dz`` and ``(k + 1) * dz`` metres above the floor in that cell."""

    spec: GridSpec
    dz: float
    masks: NDArray[np.uint64]

    @classmethod
    def from_points(cls, spec: GridSpec, xyz: NDArray[np.floating], dz: float = 0.05,
                    min_height: float = 0.1) -> HeightColumns:
        """Columns of surface points (N, 3) world; points below ``min_height`` are floor."""
        p = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        p = p[p[:, 2] >= min_height]
        masks = np.zeros((spec.rows, spec.cols), np.uint64)
        rc = spec.to_cell(p[:, :2])
        ok = spec.inside(rc)
        k = np.clip(np.floor(p[ok, 2] / dz), 0, BINS - 1).astype(np.uint64)
        np.bitwise_or.at(masks, (rc[ok, 0], rc[ok, 1]), np.left_shift(np.uint64(1), k))
        return cls(spec, float(dz), masks)

    @classmethod
    def from_voxels(cls, voxels: object, spec: GridSpec, min_weight: float = 0.02,
                    min_height: float = 0.1) -> HeightColumns:
        """Columns of a :class:`capnav.mapping.voxel_map.VoxelMap` (the occupancy's weight and floor
        thresholds, so the two agree on what was observed)."""
        c = voxels.centers()  # type: ignore[attr-defined]
        keep = voxels.weights >= min_weight  # type: ignore[attr-defined]
        return cls.from_points(spec, c[keep], float(voxels.resolution), min_height)  # type: ignore[attr-defined]

    def window(self, lo: NDArray[np.intp], hi: NDArray[np.intp]) -> NDArray[np.uint64]:
        return self.masks[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1]


def z_mask(z0: float, z1: float, dz: float) -> np.uint64:
    """The bins of the height range [z0, z1] (m above the floor)."""
    return np.uint64(_zmask(min(z0, z1), max(z0, z1), dz))


@njit(cache=True)
def _zmask(za: float, zb: float, dz: float) -> np.uint64:
    if zb < 0.0 or za >= BINS * dz:
        return np.uint64(0)
    lo = max(int(np.floor(za / dz)), 0)
    hi = min(int(np.floor(zb / dz)), BINS - 1)
    upper = ALL if hi == BINS - 1 else (np.uint64(1) << np.uint64(hi + 1)) - np.uint64(1)
    lower = (np.uint64(1) << np.uint64(lo)) - np.uint64(1)
    return upper & ~lower


@njit(cache=True)
def _ray_clear(m: NDArray[np.uint64], r0: int, c0: int, r1: int, c1: int, ze: float, zt: float, dz: float) -> bool:
    """Exact traversal from cell (r0, c0) at height ze to (r1, c1) at zt; the start cell (where
    the robot stands) is not tested."""
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
    t_in = min(t_r, t_c, 1.0)
    while r != r1 or c != c1:
        if abs(t_r - t_c) < 1e-12:
            zc = ze + (zt - ze) * t_r
            bins = _zmask(zc - 1e-9, zc + 1e-9, dz)
            if (m[r + sr, c] & bins) != 0 or (m[r, c + sc] & bins) != 0:
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
        t_out = min(t_r, t_c, 1.0)
        za = ze + (zt - ze) * t_in
        zb = ze + (zt - ze) * t_out
        if (m[r, c] & _zmask(min(za, zb), max(za, zb), dz)) != 0:
            return False
        t_in = t_out
    return True


@njit(cache=True)
def _sees(m: NDArray[np.uint64], cands: NDArray[np.int64], targets: NDArray[np.int64], heights: NDArray[np.float64],
          eye: float, dz: float) -> NDArray[np.bool_]:
    out = np.zeros(cands.shape[0], np.bool_)
    for i in range(cands.shape[0]):
        for j in range(targets.shape[0]):
            for h in range(heights.shape[0]):
                if _ray_clear(m, cands[i, 0], cands[i, 1], targets[j, 0], targets[j, 1], eye, heights[h], dz):
                    out[i] = True
                    break
            if out[i]:
                break
    return out


class SightTest:
    """Sight of one object from any cell of a window around it, set up once per goal selection so
    that candidate cells can be tested one at a time as a search reaches them."""

    def __init__(self, occ: OccupancyGrid, footprint: NDArray[np.float64], centroid: NDArray[np.float64],
                 lo: NDArray[np.intp], hi: NDArray[np.intp], columns: HeightColumns | None = None,
                 z_range: tuple[float, float] | None = None, eye_height: float = 1.25) -> None:
        spec = occ.spec
        fp_rc = spec.to_cell(np.vstack([footprint, centroid[None, :]]))
        self.lo = np.maximum(np.minimum(lo, fp_rc.min(axis=0)), 0)
        self.hi = np.minimum(np.maximum(hi, fp_rc.max(axis=0)), [spec.rows - 1, spec.cols - 1])
        lo, hi = self.lo, self.hi
        window = occ.cells[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1]
        own = np.zeros(window.shape, dtype=bool)
        # The object's own cells lie in its box grown by half a cell: measure only those.
        half = 0.5 * spec.resolution
        a = np.maximum(spec.to_cell(footprint.min(axis=0) - half), lo)
        b = np.minimum(spec.to_cell(footprint.max(axis=0) + half), hi)
        if (a <= b).all():
            rr, cc = np.mgrid[a[0]:b[0] + 1, a[1]:b[1] + 1]
            centres = spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
            own[rr - lo[0], cc - lo[1]] = (polygon_distance(centres, footprint) <= half + 1e-9).reshape(rr.shape)
        blocked = (window == OCCUPIED) & ~own
        if columns is None or columns.spec != spec:
            self.dz = 0.05
            m = np.where(blocked, ALL, np.uint64(0)).astype(np.uint64)
            self.heights = np.array([eye_height])
            self.three_d = False
        else:
            self.dz = columns.dz
            m = columns.window(lo, hi).copy()
            m[blocked & (m == 0)] = ALL  # occupied with no voxel column: a contact mark, say
            zlo, zhi = z_range if z_range is not None else (0.0, eye_height)
            zlo, zhi = max(float(zlo), 0.0), max(float(zhi), float(zlo) + self.dz)
            m[own] &= np.bitwise_not(np.uint64(z_mask(zlo - self.dz, zhi + self.dz, self.dz)))
            self.heights = np.array([0.5 * (zlo + zhi), zhi - 0.5 * self.dz])
            self.three_d = True
        self.masks = np.ascontiguousarray(m)
        self.eye = float(eye_height)
        self.targets = _targets(own, spec.to_cell(centroid) - lo, own.shape)

    def __call__(self, cells: NDArray[np.integer]) -> NDArray[np.bool_]:
        """For each of ``cells`` (N, 2) row, col inside the window, whether the object is in sight."""
        c = np.asarray(cells, dtype=np.int64).reshape(-1, 2) - self.lo
        if len(c) == 0:
            return np.zeros(0, dtype=bool)
        inside = ((c >= 0) & (c <= self.hi - self.lo)).all(axis=1)
        out = np.zeros(len(c), dtype=bool)
        out[inside] = _sees(self.masks, np.ascontiguousarray(c[inside]), self.targets, self.heights, self.eye,
                            self.dz)
        return out


def sees_footprint(occ: OccupancyGrid, footprint: NDArray[np.float64], cells: NDArray[np.integer],
                   centroid: NDArray[np.float64], columns: HeightColumns | None = None,
                   z_range: tuple[float, float] | None = None, eye_height: float = 1.25) -> NDArray[np.bool_]:
    """For each of ``cells`` (N, 2) row, col, whether a straight line from the eye above its
    centre reaches the object (footprint (K, 2), heights ``z_range``) unblocked (see the module
    notes). Without ``columns`` every occupied cell blocks at every height (the 2D test).

    Works on the window spanning the cells and the footprint only, so its cost grows with the
    number of candidates, not with the map."""
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if len(cells) == 0:
        return np.zeros(0, dtype=bool)
    test = SightTest(occ, footprint, centroid, cells.min(axis=0), cells.max(axis=0), columns, z_range, eye_height)
    return test(cells)


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


def map_columns(cmap: object) -> HeightColumns | None:
    """The observed heights of a :class:`capnav.mapping.cmap.CapNavMap` on its occupancy grid, or
    None for a map without voxels (opened with ``voxels=False``): sight is then the 2D test."""
    voxels = getattr(cmap, "voxels", None)
    occ = getattr(cmap, "occupancy", None)
    if voxels is None or occ is None or len(voxels) == 0:
        return None
    return HeightColumns.from_voxels(voxels, occ.spec)


def object_heights(obj: object) -> tuple[float, float] | None:
    """An object's height range (m above the floor) from its 3D box, None when it has none."""
    lo, hi = getattr(obj, "extent_min", None), getattr(obj, "extent_max", None)
    if lo is None or hi is None or len(lo) < 3 or len(hi) < 3:
        return None
    z0, z1 = float(lo[2]), float(hi[2])
    return (z0, z1) if np.isfinite([z0, z1]).all() and z1 >= z0 else None
