"""Distance from many grid cells to one footprint, compiled: goal selection measures every cell
of the window around an object (thousands of cells, hull footprints of tens of vertices) on each
request, where the vectorised :func:`capnav.core.footprint.footprint_distance` builds (N, K)
temporaries. Same result: the distance to the nearest edge, 0 inside (even-odd rule)."""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray


@njit(cache=True)
def _distance(pts: NDArray[np.float64], poly: NDArray[np.float64]) -> NDArray[np.float64]:
    n, k = pts.shape[0], poly.shape[0]
    out = np.empty(n, np.float64)
    for i in range(n):
        px, py = pts[i, 0], pts[i, 1]
        best = np.inf
        inside = False
        for j in range(k):
            ax, ay = poly[j, 0], poly[j, 1]
            bx, by = poly[(j + 1) % k, 0], poly[(j + 1) % k, 1]
            dx, dy = bx - ax, by - ay
            den = max(dx * dx + dy * dy, 1e-18)
            t = min(max(((px - ax) * dx + (py - ay) * dy) / den, 0.0), 1.0)
            ex, ey = px - (ax + t * dx), py - (ay + t * dy)
            best = min(best, ex * ex + ey * ey)
            if (ay > py) != (by > py) and px < ax + (py - ay) * dx / (by - ay):
                inside = not inside
        out[i] = 0.0 if inside and k > 2 else np.sqrt(best)
    return out


def polygon_distance(points: NDArray[np.floating], polygon: NDArray[np.floating]) -> NDArray[np.float64]:
    """Euclidean distance (m) from each of ``points`` (N, 2) to the polygon (K, 2); 0 inside."""
    p = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 2))
    poly = np.ascontiguousarray(np.asarray(polygon, dtype=np.float64).reshape(-1, 2))
    return _distance(p, poly)
