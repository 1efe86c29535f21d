"""An occupancy grid built online from the agent's own depth, for exploration without a prior map.

Each frame's depth is back-projected (eq. 2-3) on a pixel lattice (every ``pixel_stride``-th pixel
in u and v); points in a height band become obstacle evidence, points on the floor free evidence,
and the 2D rays from the camera to floor and obstacle points clear the cells they cross. Evidence
is counted per frame, and a cell is an obstacle when its obstacle count, weighted, is at least its
free count: a wall seen once stays a wall, while a speckle of depth noise in a cell seen free many
times does not block a door.

A map may start from a prior grid (``prior``: a saved map's occupancy): its cells stand wherever
the agent's own depth has said nothing yet, and the agent's evidence replaces them cell by cell,
so a chair that left its place is seen free again as soon as the robot looks there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import backproject
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid


@dataclass(frozen=True)
class OnlineMapConfig:
    """How depth becomes occupancy. Heights are world z (floor at 0), lengths metres."""

    resolution: float = 0.05
    half_extent: float = 16.0  # the grid covers start +- this; points outside are ignored
    floor_max_z: float = 0.05  # points below: floor, free
    obstacle_min_z: float = 0.08  # points in [min, max]: obstacles the base can hit
    obstacle_max_z: float = 1.60  # higher points (ceiling, wall-hung shelves) clear the 1.5 m agent
    max_range: float = 5.0  # depth beyond this is cut: far depth is noisy and clears too much
    # Every n-th pixel in u and v. Evidence is counted once per cell and frame, so density only has
    # to cover cells: at 320 px over 90 degrees a stride of 2 spaces points 3.1 cm apart at 5 m,
    # finer than a 5 cm cell, for a quarter of the work of every pixel.
    pixel_stride: int = 2
    clear_below_z: float = 1.60  # rays to obstacle points lower than this clear the floor before them
    obstacle_weight: float = 4.0  # obstacle if weight * obstacle_frames >= free_frames
    robot_radius: float = 0.18  # footprint marked free where the agent stands (it cannot see it)
    forgive_free_frames: int = 3  # a contact mark on a cell seen free this often may be forgiven (``cells``)

    def __post_init__(self) -> None:
        if not (self.resolution > 0 and self.half_extent > self.resolution):
            raise InputError(f"bad online map size: resolution {self.resolution}, half_extent {self.half_extent}")
        if not self.floor_max_z < self.obstacle_min_z < self.obstacle_max_z:
            raise InputError("need floor_max_z < obstacle_min_z < obstacle_max_z")
        if self.pixel_stride < 1 or self.max_range <= 0:
            raise InputError("pixel_stride must be >= 1 and max_range > 0")


class OnlineMap:
    """Occupancy evidence accumulated from posed depth frames, centred on where the agent started."""

    def __init__(self, center_xy: tuple[float, float], config: OnlineMapConfig | None = None,
                 prior: OccupancyGrid | None = None) -> None:
        self.config = cfg = config or OnlineMapConfig()
        n = int(np.ceil(2 * cfg.half_extent / cfg.resolution))
        self.spec = GridSpec(float(center_xy[0]) - cfg.half_extent, float(center_xy[1]) - cfg.half_extent,
                             cfg.resolution, n, n)
        self._free = np.zeros((n, n), np.int32)
        self._occ = np.zeros((n, n), np.int32)
        self._forced_free = np.zeros((n, n), bool)
        self._forced_occ = np.zeros((n, n), bool)
        self._stamp_free = np.zeros((n, n), np.int32)
        self._stamp_occ = np.zeros((n, n), np.int32)
        self.frames_seen = 0
        self._lattice_mask: NDArray[np.bool_] | None = None
        self._prior = _resample(prior, self.spec) if prior is not None else None

    # ------------------------------------------------------------------ updates
    def update(self, frame: Frame) -> None:
        """Fuse one posed depth frame."""
        cfg = self.config
        pts, _ = backproject(frame.depth, frame.K, frame.T_wc, mask=self._lattice(frame.K.height, frame.K.width))
        cam = np.asarray(frame.T_wc, dtype=np.float64)[:3, 3]
        xy = pts[:, :2].astype(np.float64)
        dist = np.hypot(xy[:, 0] - cam[0], xy[:, 1] - cam[1])
        z = pts[:, 2]
        in_range = dist <= cfg.max_range
        kind = np.zeros(len(pts), np.int8)
        kind[(z <= cfg.floor_max_z) & in_range] = 1
        band = (z >= cfg.obstacle_min_z) & (z <= cfg.obstacle_max_z) & in_range
        kind[band] = 2
        kind[band & (z <= cfg.clear_below_z)] = 3
        keep = kind > 0
        sp = self.spec
        # Continuous cell coordinates (row from y, col from x), as the grid convention says.
        rc = np.stack([(xy[keep, 1] - sp.y0) / sp.resolution, (xy[keep, 0] - sp.x0) / sp.resolution], axis=1)
        cam_rc = np.array([(cam[1] - sp.y0) / sp.resolution, (cam[0] - sp.x0) / sp.resolution])
        self.frames_seen += 1
        _fuse(self._free, self._occ, self._stamp_free, self._stamp_occ, self.frames_seen, cam_rc, rc, kind[keep])

    def mark_free_disk(self, xy: NDArray[np.floating] | tuple[float, float], radius: float | None = None) -> None:
        """Declare the disk the agent stands on free: the camera never sees its own footprint."""
        cells = self._disk(xy, self.config.robot_radius if radius is None else radius)
        self._forced_free[cells[:, 0], cells[:, 1]] = True
        self._forced_occ[cells[:, 0], cells[:, 1]] = False

    def mark_obstacle(self, xy: NDArray[np.floating] | tuple[float, float], radius: float = 0.08) -> None:
        """Record an obstacle found by contact (something depth did not show, e.g. below the band)."""
        cells = self._disk(xy, radius)
        keep = ~self._forced_free[cells[:, 0], cells[:, 1]]
        self._forced_occ[cells[keep, 0], cells[keep, 1]] = True

    def copy(self) -> OnlineMap:
        """An independent copy (a per-episode map that starts from a shared one)."""
        out = OnlineMap.__new__(OnlineMap)
        out.config, out.spec, out.frames_seen = self.config, self.spec, self.frames_seen
        out._lattice_mask = self._lattice_mask
        out._prior = self._prior
        for name in ("_free", "_occ", "_forced_free", "_forced_occ", "_stamp_free", "_stamp_occ"):
            setattr(out, name, getattr(self, name).copy())
        return out

    # ------------------------------------------------------------------ queries
    def cells(self, forgive_contacts: bool = False) -> NDArray[np.uint8]:
        """FREE / OCCUPIED / UNKNOWN per cell under the evidence rule of the module docstring.

        ``forgive_contacts``: leave out the contact marks on cells the depth has seen free in at
        least ``forgive_free_frames`` frames and that its evidence alone calls free. A contact is stamped where
        the robot guessed it (straight ahead); a graze of a door post puts it in the doorway,
        where it closes the door for good. A planner that finds nothing reachable may try
        without them; the next contact there marks the cell again."""
        cfg = self.config
        occ = (self._occ > 0) & (cfg.obstacle_weight * self._occ >= self._free)
        out = np.full(self._free.shape, UNKNOWN, np.uint8) if self._prior is None else self._prior.copy()
        out[(self._free > 0) & ~occ] = FREE
        out[occ] = OCCUPIED
        out[self._forced_free] = FREE
        forced = self._forced_occ
        if forgive_contacts:
            forced = forced & ~((self._free >= cfg.forgive_free_frames) & ~occ)
        out[forced] = OCCUPIED
        return out

    def grid(self, forgive_contacts: bool = False) -> OccupancyGrid:
        return OccupancyGrid(self.spec, self.cells(forgive_contacts))

    def known_fraction(self) -> float:
        """The share of cells the agent's own depth has spoken for (the prior not counted)."""
        return float(((self._free > 0) | (self._occ > 0)).mean())

    def observed(self) -> NDArray[np.bool_]:
        """Cells the agent's own depth has spoken for."""
        return (self._free > 0) | (self._occ > 0)

    # ------------------------------------------------------------------ helpers
    def _lattice(self, height: int, width: int) -> NDArray[np.bool_]:
        """The pixels that are back-projected (cached per image size)."""
        m = self._lattice_mask
        if m is None or m.shape != (height, width):
            s = self.config.pixel_stride
            m = np.zeros((height, width), bool)
            m[::s, ::s] = True
            self._lattice_mask = m
        return m

    def _disk(self, xy: NDArray[np.floating] | tuple[float, float], radius: float) -> NDArray[np.intp]:
        rc = self.spec.to_cell(np.asarray(xy, dtype=np.float64))
        k = int(np.ceil(radius / self.spec.resolution))
        rr, cc = np.mgrid[-k:k + 1, -k:k + 1]
        keep = (rr**2 + cc**2) * self.spec.resolution**2 <= radius**2 + 1e-12
        cells = np.stack([rr[keep] + rc[0], cc[keep] + rc[1]], axis=1)
        return cells[self.spec.inside(cells)]


def _resample(grid: OccupancyGrid, spec: GridSpec) -> NDArray[np.uint8]:
    """``grid``'s cells read at the centres of ``spec``'s cells (nearest cell; UNKNOWN outside it)."""
    rr, cc = np.mgrid[0:spec.rows, 0:spec.cols]
    xy = spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
    src = grid.spec.to_cell(xy)
    inside = grid.spec.inside(src)
    out = np.full(spec.rows * spec.cols, UNKNOWN, np.uint8)
    out[inside] = grid.cells[src[inside, 0], src[inside, 1]]
    return out.reshape(spec.rows, spec.cols)


@njit(cache=True)
def _fuse(free: NDArray[np.int32], occ: NDArray[np.int32], stamp_free: NDArray[np.int32],
          stamp_occ: NDArray[np.int32], frame_id: int, cam_rc: NDArray[np.float64], pts_rc: NDArray[np.float64],
          kind: NDArray[np.int8]) -> None:
    """Count one frame's evidence: each cell at most once per frame per kind (the stamps).

    ``kind`` 1 (floor), 2 (obstacle that clears nothing), 3 (obstacle whose ray clears). First every
    obstacle point marks its cell; then rays to floor and kind-3 points are walked from the camera
    in half-cell steps and clear the cells they cross, up to one cell short of the end; a floor end
    point is free. A ray passes over low furniture on its way, so furniture cells get free
    evidence too; the obstacle evidence from their surface points outweighs it (the
    ``obstacle_weight`` rule), while rays are what show the floor near walls that the camera's
    lowest view line overshoots.
    """
    rows, cols = free.shape
    for i in range(pts_rc.shape[0]):
        if kind[i] >= 2:
            r = int(np.floor(pts_rc[i, 0]))
            c = int(np.floor(pts_rc[i, 1]))
            if 0 <= r < rows and 0 <= c < cols and stamp_occ[r, c] != frame_id:
                stamp_occ[r, c] = frame_id
                occ[r, c] += 1
    for i in range(pts_rc.shape[0]):
        if kind[i] == 2:
            continue
        er, ec = pts_rc[i, 0], pts_rc[i, 1]
        dr, dc = er - cam_rc[0], ec - cam_rc[1]
        length = np.sqrt(dr * dr + dc * dc)
        n = int(max(length - 1.0, 0.0) / 0.5)
        if length > 0:
            ur, uc = dr / length * 0.5, dc / length * 0.5
            for k in range(n):
                qr = int(np.floor(cam_rc[0] + ur * k))
                qc = int(np.floor(cam_rc[1] + uc * k))
                if not (0 <= qr < rows and 0 <= qc < cols):
                    continue
                if stamp_free[qr, qc] != frame_id:
                    stamp_free[qr, qc] = frame_id
                    free[qr, qc] += 1
        r = int(np.floor(er))
        c = int(np.floor(ec))
        if kind[i] == 1 and 0 <= r < rows and 0 <= c < cols and stamp_free[r, c] != frame_id:
            stamp_free[r, c] = frame_id
            free[r, c] += 1
