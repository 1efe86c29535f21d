"""Numba kernel of a map update: what a new depth image says about points the old map holds.

For each point (world frame) the camera sees: SEEN when the observed depth at its pixel is within
``tol`` of the point's depth, THROUGH when the depth reaches more than ``margin`` past it (the
space the point occupied is free now), OCCLUDED when something nearer hides it. Pixels without
depth say nothing (a window, a missed return): silence is not evidence.
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numpy.typing import NDArray

NONE, SEEN, THROUGH, OCCLUDED = 0, 1, 2, 3


@nb.njit(cache=True, nogil=True)
def classify_points(points: NDArray[np.float64], T_cw: NDArray[np.float64], fx: float, fy: float, cx: float,
                    cy: float, depth: NDArray[np.float32], near: float, far: float, tol: float,
                    margin: float) -> NDArray[np.int8]:
    """(N,) codes NONE / SEEN / THROUGH / OCCLUDED of world points against one depth image."""
    n = points.shape[0]
    h, w = depth.shape
    out = np.zeros(n, dtype=np.int8)
    for i in range(n):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        zc = T_cw[2, 0] * x + T_cw[2, 1] * y + T_cw[2, 2] * z + T_cw[2, 3]
        if zc < near or zc > far:
            continue
        xc = T_cw[0, 0] * x + T_cw[0, 1] * y + T_cw[0, 2] * z + T_cw[0, 3]
        yc = T_cw[1, 0] * x + T_cw[1, 1] * y + T_cw[1, 2] * z + T_cw[1, 3]
        u = int(np.floor(fx * xc / zc + cx))
        v = int(np.floor(fy * yc / zc + cy))
        if u < 0 or v < 0 or u >= w or v >= h:
            continue
        d = depth[v, u]
        if not (d > 0.0) or not np.isfinite(d):
            continue
        if abs(d - zc) <= tol:
            out[i] = SEEN
        elif d > zc + margin:
            out[i] = THROUGH
        elif d < zc - tol:
            out[i] = OCCLUDED
    return out
