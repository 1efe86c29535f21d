"""Primitive parts and 2D oriented rectangles: the geometry the world, collision and tests share."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Part:
    """One primitive of a piece of furniture, in the object's local frame (z up, origin on the floor).

    ``kind`` is "box", "cylinder" or "sphere"; ``size`` is the full extent (x, y, z) of the part
    (a cylinder's diameter is ``size[0]``, a sphere's diameter too); ``axis`` is the cylinder axis
    ("x", "y" or "z"); ``role`` names which colour / material of the instance it takes
    ("main", "accent", "legs", "metal", "white", "dark", "glass", "leaf", "soil", "book:<k>").
    """

    kind: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]
    role: str = "main"
    axis: str = "z"


def box(cx: float, cy: float, cz: float, sx: float, sy: float, sz: float, role: str = "main") -> Part:
    return Part("box", (cx, cy, cz), (sx, sy, sz), role)


def cyl(cx: float, cy: float, cz: float, d: float, h: float, role: str = "main", axis: str = "z") -> Part:
    size = {"z": (d, d, h), "x": (h, d, d), "y": (d, h, d)}[axis]
    return Part("cylinder", (cx, cy, cz), size, role, axis)


def sphere(cx: float, cy: float, cz: float, d: float, role: str = "main") -> Part:
    return Part("sphere", (cx, cy, cz), (d, d, d), role)


def rot2(yaw: float) -> F64:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s], [s, c]])


def rect_corners(center: tuple[float, float], size: tuple[float, float], yaw: float) -> F64:
    """4 world corners (counter-clockwise) of a rectangle of full ``size`` rotated by ``yaw``."""
    hx, hy = size[0] / 2.0, size[1] / 2.0
    local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    return local @ rot2(yaw).T + np.asarray(center, dtype=np.float64)


@dataclass
class RectSet:
    """N oriented rectangles (walls, furniture footprints) for vectorised distance queries."""

    center: F64  # (N, 2)
    half: F64  # (N, 2)
    cos: F64  # (N,)
    sin: F64  # (N,)

    @classmethod
    def from_lists(cls, centers: list[tuple[float, float]], sizes: list[tuple[float, float]],
                   yaws: list[float]) -> RectSet:
        yaw = np.asarray(yaws, dtype=np.float64).reshape(-1)
        return cls(np.asarray(centers, dtype=np.float64).reshape(-1, 2),
                   np.asarray(sizes, dtype=np.float64).reshape(-1, 2) / 2.0, np.cos(yaw), np.sin(yaw))

    def __len__(self) -> int:
        return int(self.center.shape[0])

    def signed_distance(self, pts: F64) -> F64:
        """(M, N) signed distance from each of M points to each rectangle (negative inside)."""
        d = np.asarray(pts, dtype=np.float64)[:, None, :] - self.center[None, :, :]
        lx = np.abs(d[..., 0] * self.cos + d[..., 1] * self.sin) - self.half[:, 0]
        ly = np.abs(-d[..., 0] * self.sin + d[..., 1] * self.cos) - self.half[:, 1]
        outside = np.hypot(np.maximum(lx, 0.0), np.maximum(ly, 0.0))
        inside = np.minimum(np.maximum(lx, ly), 0.0)
        return np.asarray(outside + inside)

    def distance_grid(self, x0: float, y0: float, res: float, rows: int, cols: int, cap: float) -> F64:
        """(rows, cols) distance from each cell centre to the nearest rectangle, capped at ``cap``.

        Each rectangle only touches the cells of its bounding box grown by ``cap``, which makes this
        far cheaper than ``min_distance`` over all cells.
        """
        out = np.full((rows, cols), cap, dtype=np.float64)
        ext = np.abs(self.half[:, 0] * self.cos) + np.abs(self.half[:, 1] * self.sin), \
            np.abs(self.half[:, 0] * self.sin) + np.abs(self.half[:, 1] * self.cos)
        for k in range(len(self)):
            cx, cy = self.center[k]
            c0 = max(0, int(np.floor((cx - ext[0][k] - cap - x0) / res)))
            c1 = min(cols, int(np.ceil((cx + ext[0][k] + cap - x0) / res)) + 1)
            r0 = max(0, int(np.floor((cy - ext[1][k] - cap - y0) / res)))
            r1 = min(rows, int(np.ceil((cy + ext[1][k] + cap - y0) / res)) + 1)
            if c0 >= c1 or r0 >= r1:
                continue
            xs = x0 + (np.arange(c0, c1) + 0.5) * res - cx
            ys = y0 + (np.arange(r0, r1) + 0.5) * res - cy
            dx, dy = xs[None, :], ys[:, None]
            lx = np.abs(dx * self.cos[k] + dy * self.sin[k]) - self.half[k, 0]
            ly = np.abs(-dx * self.sin[k] + dy * self.cos[k]) - self.half[k, 1]
            d = np.hypot(np.maximum(lx, 0.0), np.maximum(ly, 0.0)) + np.minimum(np.maximum(lx, ly), 0.0)
            np.minimum(out[r0:r1, c0:c1], d, out=out[r0:r1, c0:c1])
        return out

    def min_distance(self, pts: F64) -> F64:
        """(M,) distance from each point to the nearest rectangle (inf when the set is empty)."""
        pts = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
        if len(self) == 0:
            return np.full(pts.shape[0], np.inf)
        out = np.empty(pts.shape[0])
        for s in range(0, pts.shape[0], 4096):  # bound the (M, N) temporary
            out[s:s + 4096] = self.signed_distance(pts[s:s + 4096]).min(axis=1)
        return out


def rects_overlap(a: F64, b: F64, margin: float = 0.0) -> bool:
    """Separating-axis test of two convex quads given as (4, 2) corners, grown by ``margin``."""
    for poly in (a, b):
        for i in range(4):
            edge = poly[(i + 1) % 4] - poly[i]
            n = np.array([-edge[1], edge[0]])
            n /= np.linalg.norm(n) + 1e-12
            pa, pb = a @ n, b @ n
            if pa.max() + margin <= pb.min() or pb.max() + margin <= pa.min():
                return False
    return True


def part_surface_distance(pts: F64, part: Part, T: F64) -> F64:
    """Unsigned distance of world points to the surface of ``part`` placed by the 4x4 object pose ``T``.

    Used by tests to check that back-projected depth lands on the true surfaces.
    """
    p = (np.asarray(pts, dtype=np.float64) - T[:3, 3]) @ T[:3, :3]  # into the object frame
    p = p - np.asarray(part.center)
    h = np.asarray(part.size) / 2.0
    if part.kind == "box":
        q = np.abs(p) - h
        outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
        inside = np.minimum(q.max(axis=1), 0.0)
        return np.asarray(np.abs(outside + inside))
    if part.kind == "sphere":
        return np.asarray(np.abs(np.linalg.norm(p, axis=1) - h[0]))
    ax = "xyz".index(part.axis)
    others = [i for i in range(3) if i != ax]
    r = np.linalg.norm(p[:, others], axis=1) - h[others[0]]
    a = np.abs(p[:, ax]) - h[ax]
    outside = np.hypot(np.maximum(r, 0.0), np.maximum(a, 0.0))
    inside = np.minimum(np.maximum(r, a), 0.0)
    return np.asarray(np.abs(outside + inside))
