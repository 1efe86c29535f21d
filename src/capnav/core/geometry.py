"""Camera model and poses (paper eq. 1-3) in CapNav's conventions.

World frame: right-handed, z up, floor at z = 0, metres. Camera frame: OpenCV (x right, y down,
z forward). A pose is the 4x4 camera-to-world matrix ``T_wc`` (eq. 3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, PoseError

FloatArray = NDArray[np.floating]


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of eq. 1 plus the image size they belong to."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self) -> None:
        vals = (self.fx, self.fy, self.cx, self.cy)
        if not all(np.isfinite(v) for v in vals) or self.fx <= 0 or self.fy <= 0:
            raise InputError(f"intrinsics must be finite with fx, fy > 0, got {vals}")
        if self.width <= 0 or self.height <= 0:
            raise InputError(f"image size must be positive, got {self.width}x{self.height}")

    @property
    def K(self) -> NDArray[np.float64]:
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @classmethod
    def from_fov(cls, width: int, height: int, vfov_deg: float) -> Intrinsics:
        """Square pixels, principal point at the image centre, vertical field of view in degrees."""
        fy = 0.5 * height / np.tan(np.deg2rad(vfov_deg) / 2.0)
        return cls(fx=float(fy), fy=float(fy), cx=width / 2.0, cy=height / 2.0, width=width, height=height)

    @classmethod
    def from_matrix(cls, K: FloatArray, width: int, height: int) -> Intrinsics:
        K = np.asarray(K, dtype=np.float64)
        if K.shape != (3, 3):
            raise InputError(f"K must be 3x3, got shape {K.shape}")
        return cls(float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2]), int(width), int(height))

    def scaled(self, width: int, height: int) -> Intrinsics:
        sx, sy = width / self.width, height / self.height
        return Intrinsics(self.fx * sx, self.fy * sy, self.cx * sx, self.cy * sy, width, height)

    def to_dict(self) -> dict[str, float | int]:
        return {"fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy, "width": self.width, "height": self.height}


def check_pose(T_in: FloatArray, frame: int | str = "?", tol: float = 1e-3) -> NDArray[np.float64]:
    """Return ``T`` as float64 4x4 if it is a rigid transform, else raise ``PoseError`` naming ``frame``.

    Rigid means: finite, last row [0 0 0 1], rotation orthonormal with det +1. Wrong pose
    conventions are the most reported failure in peer projects, so every loader calls this.
    """
    T: NDArray[np.float64] = np.asarray(T_in, dtype=np.float64)
    if T.shape != (4, 4):
        raise PoseError(frame, f"pose must be 4x4, got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise PoseError(frame, "pose has non-finite entries")
    if not np.allclose(T[3], [0.0, 0.0, 0.0, 1.0], atol=tol):
        raise PoseError(frame, f"pose last row must be [0 0 0 1], got {T[3].tolist()}")
    R = T[:3, :3]
    ortho_err = float(np.abs(R.T @ R - np.eye(3)).max())
    if ortho_err > tol:
        raise PoseError(frame, f"rotation is not orthonormal (max |R^T R - I| = {ortho_err:.3g})")
    det = float(np.linalg.det(R))
    if det < 0:
        raise PoseError(frame, f"rotation has det {det:.3f} (a reflection: left-handed frame?)")
    return T


def backproject(depth: FloatArray, K: Intrinsics, T_wc: FloatArray | None = None,
                mask: NDArray[np.bool_] | None = None) -> tuple[NDArray[np.float32], NDArray[np.intp]]:
    """Lift valid depth pixels to 3D (eq. 2-3).

    Returns ``(points, flat_index)``: ``points`` (N, 3) in the world frame if ``T_wc`` is given
    (else camera frame), and the flat pixel index ``v * W + u`` of each point. Invalid depth
    (0 or non-finite) is skipped, and so are pixels outside ``mask`` when one is given.
    """
    depth = np.asarray(depth)
    if depth.shape != (K.height, K.width):
        raise InputError(f"depth shape {depth.shape} does not match intrinsics {K.height}x{K.width}")
    valid = np.isfinite(depth) & (depth > 0)
    if mask is not None:
        valid &= mask
    flat = np.flatnonzero(valid)
    z = depth.reshape(-1)[flat].astype(np.float32)
    v, u = np.divmod(flat, K.width)
    x = (u.astype(np.float32) - np.float32(K.cx)) * z / np.float32(K.fx)
    y = (v.astype(np.float32) - np.float32(K.cy)) * z / np.float32(K.fy)
    pts = np.stack([x, y, z], axis=1)
    if T_wc is not None:
        T = np.asarray(T_wc, dtype=np.float32)
        pts = pts @ T[:3, :3].T + T[:3, 3]
    return pts.astype(np.float32, copy=False), flat


def project(points_w: FloatArray, K: Intrinsics, T_wc: FloatArray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Project world points into the image: returns pixel coords (N, 2) as (u, v) and depth z (N,)."""
    T_cw = np.linalg.inv(np.asarray(T_wc, dtype=np.float64))
    pc = np.asarray(points_w, dtype=np.float64) @ T_cw[:3, :3].T + T_cw[:3, 3]
    z = pc[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = K.fx * pc[:, 0] / z + K.cx
        v = K.fy * pc[:, 1] / z + K.cy
    return np.stack([u, v], axis=1), z


def look_at_pose(eye: FloatArray, yaw: float, pitch: float = 0.0) -> NDArray[np.float64]:
    """Camera-to-world pose of an OpenCV camera at ``eye`` looking along ``yaw`` (radians, from +x
    towards +y in the z-up world) tilted down by ``pitch`` radians."""
    fwd = np.array([np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), -np.sin(pitch)])
    right = np.array([np.sin(yaw), -np.cos(yaw), 0.0])
    down = np.cross(fwd, right)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = right, down, fwd, np.asarray(eye, dtype=np.float64)
    return T
