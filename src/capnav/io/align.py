"""Gravity / floor alignment of an imported recording into CapNav's world (z up, floor at z = 0).

Recordings come in whatever world their tracker chose (TUM: the first camera's frame, y down;
odometry: the robot's start, z up but the floor at -0.3 m ...). The occupancy map and object
heights need the floor at z = 0, so the importer finds a rigid transform ``A`` and writes
``T_wc' = A @ T_wc`` for every frame. The user names the approximate up axis; the floor plane
fitted to back-projected depth refines it (the floor: the lowest near-horizontal plane with
enough support, not a table top). Yaw and the horizontal origin stay as recorded.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics, backproject

AXES = {"+x": (1.0, 0.0, 0.0), "-x": (-1.0, 0.0, 0.0), "+y": (0.0, 1.0, 0.0), "-y": (0.0, -1.0, 0.0),
        "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0)}
UP_CHOICES = (*AXES, "none")


def parse_up(up: str) -> NDArray[np.float64] | None:
    """The up axis named by ``--up`` (``+z``, ``-y``, ``y`` = ``+y``, ...) or None for ``none``."""
    key = up.strip().lower()
    if key == "none":
        return None
    if len(key) == 1:
        key = "+" + key
    if key not in AXES:
        raise InputError(f"--up must be one of {', '.join(UP_CHOICES)}, got {up!r}")
    return np.array(AXES[key])


def rotation_between(a: NDArray[np.floating], b: NDArray[np.floating]) -> NDArray[np.float64]:
    """The smallest rotation taking unit direction ``a`` to ``b`` (Rodrigues; a half turn for opposites)."""
    a = np.asarray(a, dtype=np.float64) / np.linalg.norm(a)
    b = np.asarray(b, dtype=np.float64) / np.linalg.norm(b)
    v, c = np.cross(a, b), float(a @ b)
    if c < -1.0 + 1e-12:  # opposite: turn half a circle about any axis perpendicular to a
        p = np.eye(3)[int(np.argmin(np.abs(a)))]
        axis = np.cross(a, p)
        axis /= np.linalg.norm(axis)
        return 2.0 * np.outer(axis, axis) - np.eye(3)
    vx = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


@dataclass(frozen=True)
class FloorConfig:
    """Floor search knobs: a horizontal plane within ``max_tilt_deg`` of the named up axis."""

    max_tilt_deg: float = 20.0
    inlier_dist: float = 0.03  # metres
    iterations: int = 400
    points_per_frame: int = 3000
    max_range: float = 6.0  # far depth is noisy; the floor near the camera is enough
    min_support: float = 0.2  # of the best horizontal plane's inliers (so a small table top loses)
    min_points: int = 200
    seed: int = 0


@dataclass
class Alignment:
    """The rigid transform applied to every pose, and how it was found (recorded in the dataset meta)."""

    A: NDArray[np.float64]
    up: str
    info: dict[str, Any] = field(default_factory=dict)

    def to_meta(self) -> dict[str, Any]:
        return {"up": self.up, "A": [float(v) for v in self.A.reshape(-1)], **self.info}


def identity(up: str = "none") -> Alignment:
    return Alignment(np.eye(4), up, {"method": "none"})


def floor_points(views: Iterable[tuple[NDArray[np.floating], NDArray[np.floating]]], K: Intrinsics,
                 cfg: FloorConfig) -> NDArray[np.float64]:
    """World points from ``(depth, T_wc)`` pairs, a random subsample per frame within ``max_range``."""
    rng = np.random.default_rng(cfg.seed)
    chunks = []
    for depth, T in views:
        d = np.asarray(depth, dtype=np.float32)
        pts, _ = backproject(d, K, T, mask=d < cfg.max_range)
        if len(pts) > cfg.points_per_frame:
            pts = pts[rng.choice(len(pts), cfg.points_per_frame, replace=False)]
        chunks.append(pts.astype(np.float64))
    return np.concatenate(chunks) if chunks else np.zeros((0, 3))


def fit_floor(points: NDArray[np.floating], up: NDArray[np.floating],
              cfg: FloorConfig | None = None) -> tuple[NDArray[np.float64], float, dict[str, Any]]:
    """Fit the floor plane ``n . p = d`` (``n`` unit, pointing along ``up``) to world ``points``.

    RANSAC hypotheses from random point triples, only those within ``max_tilt_deg`` of ``up``;
    among hypotheses whose support reaches ``min_support`` of the best one, the lowest (along
    ``up``) wins, then a least-squares refit on its inliers. Raises ``InputError`` when no
    horizontal plane has enough points (wrong ``--up``, or no floor in view).
    """
    cfg = cfg or FloorConfig()
    P = np.asarray(points, dtype=np.float64)
    u = np.asarray(up, dtype=np.float64) / np.linalg.norm(up)
    if len(P) < cfg.min_points:
        raise InputError(f"floor fit: only {len(P)} depth points in the sampled frames (need {cfg.min_points})")
    rng = np.random.default_rng(cfg.seed)
    tri = P[rng.integers(0, len(P), (cfg.iterations, 3))]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1)
    good = norm > 1e-9
    n, tri = n[good] / norm[good, None], tri[good]
    n *= np.sign(n @ u)[:, None]
    cos_tilt = np.cos(np.deg2rad(cfg.max_tilt_deg))
    keep = n @ u >= cos_tilt
    n, tri = n[keep], tri[keep]
    if len(n) == 0:
        raise InputError(f"floor fit: no plane within {cfg.max_tilt_deg:.0f} degrees of the up axis {u.tolist()}")
    d = np.einsum("ij,ij->i", n, tri[:, 0])
    support = np.zeros(len(n), dtype=np.int64)
    height = np.zeros(len(n))
    hp = P @ u
    for s in range(0, len(n), 64):  # (64, N) blocks keep memory small
        inl = np.abs(n[s:s + 64] @ P.T - d[s:s + 64, None]) < cfg.inlier_dist
        support[s:s + 64] = inl.sum(axis=1)
        height[s:s + 64] = (inl * hp).sum(axis=1) / np.maximum(support[s:s + 64], 1)
    best = int(support.max())
    if best < cfg.min_points:
        raise InputError(f"floor fit: the best plane within {cfg.max_tilt_deg:.0f} degrees of up {u.tolist()} has "
                         f"only {best} points (need {cfg.min_points}); is --up right? (--up none keeps the frame)")
    cand = np.flatnonzero(support >= max(cfg.min_support * best, cfg.min_points))
    k = int(cand[np.argmin(height[cand])])
    normal, off = n[k], float(d[k])
    for _ in range(3):  # least-squares refit on the inliers
        inl = P[np.abs(P @ normal - off) < cfg.inlier_dist]
        c = inl.mean(axis=0)
        _, _, vt = np.linalg.svd(inl - c, full_matrices=False)
        normal = vt[2] * np.sign(vt[2] @ u)
        off = float(normal @ c)
    resid = inl @ normal - off
    tilt = float(np.degrees(np.arccos(np.clip(normal @ u, -1.0, 1.0))))
    return normal, off, {"floor_points": len(inl), "floor_rms_m": float(np.sqrt(np.mean(resid ** 2))),
                         "tilt_from_up_deg": tilt, "points": len(P), "best_plane_points": best}


def floor_alignment(views: Iterable[tuple[NDArray[np.floating], NDArray[np.floating]]], K: Intrinsics, up: str,
                    cfg: FloorConfig | None = None) -> Alignment:
    """``A`` that turns the fitted floor normal into +z and puts the floor at z = 0 (``up='none'``: identity)."""
    u = parse_up(up)
    if u is None:
        return identity()
    cfg = cfg or FloorConfig()
    normal, off, info = fit_floor(floor_points(views, K, cfg), u, cfg)
    A = np.eye(4)
    A[:3, :3] = rotation_between(normal, np.array([0.0, 0.0, 1.0]))
    A[2, 3] = -off  # the plane n.p = off becomes z = off after the rotation
    return Alignment(A, up, {"method": "floor-ransac", **info})
