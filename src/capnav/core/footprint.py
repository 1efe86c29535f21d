"""2D footprints (convex or simple polygons in world x, y): distances used by planning and evaluation."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError


def footprint_distance(points: NDArray[np.floating], polygon: NDArray[np.floating]) -> NDArray[np.float64]:
    """Euclidean distance (m) from each of ``points`` (N, 2) to a simple polygon (K, 2); 0 inside.

    Vectorised over points and edges: distance to every edge segment, then an even-odd
    crossing test for inside points.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
    poly = np.asarray(polygon, dtype=np.float64)
    if poly.ndim != 2 or poly.shape[1] != 2 or len(poly) < 1:
        raise InputError(f"footprint must be (K, 2), got shape {poly.shape}")
    if pts.shape[-1] != 2:
        raise InputError(f"points must be (N, 2), got shape {pts.shape}")
    if len(poly) == 1:
        return np.asarray(np.linalg.norm(pts - poly[0], axis=1), dtype=np.float64)
    a = poly[None, :, :]  # (1, K, 2)
    b = np.roll(poly, -1, axis=0)[None, :, :]
    p = pts[:, None, :]  # (N, 1, 2)
    ab = b - a
    denom = np.maximum((ab**2).sum(-1), 1e-18)
    t = np.clip(((p - a) * ab).sum(-1) / denom, 0.0, 1.0)
    closest = a + t[..., None] * ab
    d = np.sqrt(((p - closest) ** 2).sum(-1)).min(axis=1)
    # Even-odd rule: count edges whose y-span contains the point and which lie to its right.
    ay, by = a[..., 1], b[..., 1]
    py, px = p[..., 1], p[..., 0]
    straddle = (ay > py) != (by > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = a[..., 0] + (py - ay) * (b[..., 0] - a[..., 0]) / (by - ay)
    inside = (straddle & (px < x_cross)).sum(axis=1) % 2 == 1
    d[inside] = 0.0
    return np.asarray(d, dtype=np.float64)
