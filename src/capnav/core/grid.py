"""Top-down grids: cells are (row, col) with the origin and resolution stored with the map.

``row = floor((y - y0) / res)``, ``col = floor((x - x0) / res)``: rows grow with world y, columns
with world x. Images of a grid are drawn with ``origin="lower"`` so north (+y) is up.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError

FREE: int = 0
OCCUPIED: int = 1
UNKNOWN: int = 2


@dataclass(frozen=True)
class GridSpec:
    """Where a grid sits in the world: origin (x0, y0) of cell (0, 0)'s corner, cell size, shape."""

    x0: float
    y0: float
    resolution: float
    rows: int
    cols: int

    def __post_init__(self) -> None:
        if not (self.resolution > 0 and np.isfinite(self.resolution)):
            raise InputError(f"grid resolution must be positive, got {self.resolution}")
        if self.rows <= 0 or self.cols <= 0:
            raise InputError(f"grid must have at least one cell, got {self.rows}x{self.cols}")

    @classmethod
    def covering(cls, xmin: float, ymin: float, xmax: float, ymax: float, resolution: float,
                 margin: float = 0.0) -> GridSpec:
        x0, y0 = xmin - margin, ymin - margin
        cols = int(np.ceil((xmax + margin - x0) / resolution))
        rows = int(np.ceil((ymax + margin - y0) / resolution))
        return cls(float(x0), float(y0), float(resolution), max(rows, 1), max(cols, 1))

    def to_cell(self, xy: NDArray[np.floating]) -> NDArray[np.intp]:
        """World (..., 2) x, y -> integer (..., 2) row, col (may fall outside the grid)."""
        xy = np.asarray(xy, dtype=np.float64)
        col = np.floor((xy[..., 0] - self.x0) / self.resolution)
        row = np.floor((xy[..., 1] - self.y0) / self.resolution)
        return np.stack([row, col], axis=-1).astype(np.intp)

    def to_world(self, rc: NDArray[np.integer]) -> NDArray[np.float64]:
        """Cell (..., 2) row, col -> world (..., 2) x, y of the cell centre."""
        rc = np.asarray(rc, dtype=np.float64)
        x = self.x0 + (rc[..., 1] + 0.5) * self.resolution
        y = self.y0 + (rc[..., 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=-1)

    def inside(self, rc: NDArray[np.integer]) -> NDArray[np.bool_]:
        rc = np.asarray(rc)
        return (rc[..., 0] >= 0) & (rc[..., 0] < self.rows) & (rc[..., 1] >= 0) & (rc[..., 1] < self.cols)

    def to_dict(self) -> dict[str, float | int]:
        return {"x0": self.x0, "y0": self.y0, "resolution": self.resolution, "rows": self.rows, "cols": self.cols}


@dataclass
class OccupancyGrid:
    """A top-down map: ``cells`` uint8 (rows, cols) of FREE / OCCUPIED / UNKNOWN."""

    spec: GridSpec
    cells: NDArray[np.uint8] = field(repr=False)

    def __post_init__(self) -> None:
        if self.cells.shape != (self.spec.rows, self.spec.cols):
            raise InputError(f"occupancy shape {self.cells.shape} != spec ({self.spec.rows}, {self.spec.cols})")

    def blocked(self, unknown_blocked: bool = True) -> NDArray[np.bool_]:
        b = self.cells == OCCUPIED
        if unknown_blocked:
            b |= self.cells == UNKNOWN
        return b

    def inflated(self, radius: float) -> OccupancyGrid:
        """Obstacles grown by ``radius`` metres (a disk), e.g. the robot radius plus a margin."""
        from scipy import ndimage

        r = int(np.ceil(radius / self.spec.resolution))
        occ = self.cells == OCCUPIED
        if r > 0 and occ.any():
            # Distance transform gives an exact disk without building a structuring element.
            dist = ndimage.distance_transform_edt(~occ) * self.spec.resolution
            occ = dist <= radius + 1e-9  # tolerate float round-off at exact multiples of the cell size
        cells = self.cells.copy()
        cells[occ] = OCCUPIED
        return OccupancyGrid(self.spec, cells)
