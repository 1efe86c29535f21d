"""OpenGL matrices for pybullet that match an OpenCV pinhole camera exactly, and depth linearisation.

pybullet's renderer takes an OpenGL view matrix (camera x right, y up, looking down -z) and a
projection matrix, both column-major. Its tiny renderer samples column u at NDC x = 2u/W - 1 and
row v (counted from the top of the returned image) at NDC y = 1 - 2(v + 1)/H (measured: floor
depth against the analytic ray-plane hit, tests/sim/test_render.py). The frustum below puts the
OpenCV ray ((u - cx) / fx, (v - cy) / fy, 1) exactly on those samples.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from capnav.core.geometry import Intrinsics

_CV_TO_GL = np.diag([1.0, -1.0, -1.0, 1.0])


def view_matrix(T_wc: NDArray[np.float64]) -> list[float]:
    """World-to-GL-camera matrix, flattened column-major for pybullet."""
    T_gl = np.asarray(T_wc, dtype=np.float64) @ _CV_TO_GL
    return [float(v) for v in np.linalg.inv(T_gl).flatten(order="F")]


def projection_matrix(K: Intrinsics, near: float, far: float) -> list[float]:
    """GL projection whose pixel samples reproduce OpenCV's ``u = fx x / z + cx``, ``v = fy y / z + cy``."""
    W, H = K.width, K.height
    P = np.zeros((4, 4))
    P[0, 0] = 2.0 * K.fx / W
    P[0, 2] = 1.0 - 2.0 * K.cx / W
    P[1, 1] = 2.0 * K.fy / H
    P[1, 2] = (2.0 * K.cy + 2.0) / H - 1.0
    P[2, 2] = -(far + near) / (far - near)
    P[2, 3] = -2.0 * far * near / (far - near)
    P[3, 2] = -1.0
    return [float(v) for v in P.flatten(order="F")]


def linear_depth(buffer: NDArray[np.floating], near: float, far: float) -> NDArray[np.float32]:
    """Metric z-depth from the renderer's [0, 1] depth buffer: far*near / (far - (far - near) * d)."""
    d = np.asarray(buffer, dtype=np.float64)
    z = far * near / (far - (far - near) * d)
    return z.astype(np.float32)
