"""Where a robot position given with a question lands on the map.

A position off the map is an error, as a start off the map is for ``navigate``: distances from it
("the closest chair") would be measured from nowhere the map knows. A position inside an obstacle
is usually a localisation error of a few centimetres against a wall: it moves to the nearest free
cell, and the note says how far.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from capnav.core.errors import InputError
from capnav.core.grid import FREE, OCCUPIED, OccupancyGrid


def place_robot(occ: OccupancyGrid, xy: tuple[float, float], what: str = "robot") -> tuple[tuple[float, float], str]:
    """``xy`` itself with an empty note, the nearest free cell's centre with a note when ``xy`` is
    inside an obstacle, or ``InputError`` when it is off the map or the map has no free cell."""
    p = np.asarray(xy, dtype=np.float64).reshape(-1)
    if p.shape != (2,) or not np.isfinite(p).all():
        raise InputError(f"{what} must be finite numbers x, y (m), got {xy!r}")
    s = occ.spec
    rc = s.to_cell(p)
    if not s.inside(rc):
        raise InputError(
            f"{what} ({p[0]:.2f}, {p[1]:.2f}) is off the map, which covers x in [{s.x0:.2f}, "
            f"{s.x0 + s.cols * s.resolution:.2f}], y in [{s.y0:.2f}, {s.y0 + s.rows * s.resolution:.2f}]")
    r, c = int(rc[0]), int(rc[1])
    if occ.cells[r, c] != OCCUPIED:
        return (float(p[0]), float(p[1])), ""
    free = occ.cells == FREE
    if not free.any():
        raise InputError(f"{what} ({p[0]:.2f}, {p[1]:.2f}) is inside an obstacle and the map has no free cell")
    _, (ir, ic) = ndimage.distance_transform_edt(~free, return_indices=True)
    cell = np.array([int(ir[r, c]), int(ic[r, c])])
    q = s.to_world(cell)
    d = float(np.hypot(q[0] - p[0], q[1] - p[1]))
    return (round(float(q[0]), 4), round(float(q[1]), 4)), (
        f"{what} ({p[0]:.2f}, {p[1]:.2f}) is inside an obstacle; moved {d:.2f} m to the nearest free cell "
        f"({q[0]:.2f}, {q[1]:.2f})")
