"""Register a later recording to an existing map: the rigid transform from the recording's world
frame to the map's, found by ICP on the depth (Open3D) or given by the user and checked.

Two recordings of a home made on different days start wherever the robot was switched on, so
their world frames differ. The recording's depth (a spread of frames, voxel-downsampled) is
aligned to the map's voxel surface by point-to-plane ICP, coarse to fine, from the user's guess
or the identity. The result is accepted only when most of the recording's points land on the
map's surface (``min_fitness``) with a small residual (``max_rmse``): a recording of another
apartment, or one too far off to converge, is refused with both figures rather than fused.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, pip_hint
from capnav.core.frame import Frame


class RegistrationError(InputError):
    """The recording could not be aligned to the map (names the residual)."""


@dataclass(frozen=True)
class RegisterConfig:
    """ICP at ``scales`` (voxel size, max correspondence distance) in metres; accept when at least
    ``min_fitness`` of the recording's points lie within the finest distance of the map surface
    with an inlier RMSE of at most ``max_rmse``. ``frames`` spread frames feed the source cloud."""

    frames: int = 40
    pixel_stride: int = 4
    max_depth: float = 5.0
    scales: tuple[tuple[float, float], ...] = ((0.2, 1.0), (0.1, 0.4), (0.05, 0.12))
    min_fitness: float = 0.6
    max_rmse: float = 0.05
    iterations: int = 40


@dataclass
class Registration:
    """``T`` (4x4) maps recording-world points into the map frame; the check's figures."""

    T: NDArray[np.float64]
    fitness: float
    rmse: float
    method: str

    def to_dict(self) -> dict[str, Any]:
        return {"transform": np.round(self.T, 9).tolist(), "fitness": round(self.fitness, 4),
                "rmse": round(self.rmse, 5), "method": self.method}


def depth_cloud(frames: list[Frame], cfg: RegisterConfig) -> NDArray[np.float64]:
    """World points (recording frame) of every ``pixel_stride``-th valid pixel of ``frames``."""
    out = []
    for f in frames:
        d = np.asarray(f.depth, dtype=np.float64)[:: cfg.pixel_stride, :: cfg.pixel_stride]
        v, u = np.mgrid[0: f.depth.shape[0]: cfg.pixel_stride, 0: f.depth.shape[1]: cfg.pixel_stride]
        ok = np.isfinite(d) & (d > 0) & (d <= cfg.max_depth)
        z = d[ok]
        x = (u[ok] + 0.5 - f.K.cx) / f.K.fx * z
        y = (v[ok] + 0.5 - f.K.cy) / f.K.fy * z
        pc = np.stack([x, y, z, np.ones_like(z)], axis=1)
        out.append((pc @ np.asarray(f.T_wc, dtype=np.float64).T)[:, :3])
    return np.concatenate(out) if out else np.zeros((0, 3))


def _o3d() -> Any:
    try:
        import open3d as o3d
    except (ImportError, OSError):  # not installed, or a system library it needs (libusb) is missing
        raise InputError(f"registering two recordings needs Open3D ({pip_hint('capnav[register]')}); or give "
                         "the transform with --transform, or --same-frame when both share a world frame") from None
    return o3d


def _cloud(o3d: Any, pts: NDArray[np.float64], voxel: float) -> Any:
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.ascontiguousarray(pts, dtype=np.float64)))
    pc = pc.voxel_down_sample(voxel)
    pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=voxel * 2.5, max_nn=30))
    return pc


def register_icp(source: NDArray[np.float64], target: NDArray[np.float64], init: NDArray[np.float64] | None = None,
                 config: RegisterConfig | None = None) -> Registration:
    """Point-to-plane ICP of ``source`` (recording) onto ``target`` (map surface), coarse to fine."""
    cfg = config or RegisterConfig()
    if len(source) < 100 or len(target) < 100:
        raise RegistrationError(f"too few points to register ({len(source)} in the recording, {len(target)} "
                                "in the map)")
    o3d = _o3d()
    reg = o3d.pipelines.registration
    T = np.eye(4) if init is None else np.asarray(init, dtype=np.float64)
    for voxel, dist in cfg.scales:
        src, tgt = _cloud(o3d, source, voxel), _cloud(o3d, target, voxel)
        res = reg.registration_icp(src, tgt, dist, T, reg.TransformationEstimationPointToPlane(),
                                   reg.ICPConvergenceCriteria(max_iteration=cfg.iterations))
        T = np.asarray(res.transformation, dtype=np.float64)
    voxel, dist = cfg.scales[-1]
    ev = reg.evaluate_registration(_cloud(o3d, source, voxel), _cloud(o3d, target, voxel), dist, T)
    return Registration(T=T, fitness=float(ev.fitness), rmse=float(ev.inlier_rmse), method="icp")


def check_fit(source: NDArray[np.float64], target: NDArray[np.float64], T: NDArray[np.float64], dist: float
              ) -> tuple[float, float]:
    """(fitness, inlier RMSE) of ``T`` without Open3D: nearest map point of each recording point."""
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(0)
    src = source[rng.choice(len(source), min(len(source), 20000), replace=False)] if len(source) else source
    p = src @ T[:3, :3].T + T[:3, 3]
    d, _ = cKDTree(target).query(p, distance_upper_bound=dist)
    ok = np.isfinite(d)
    return float(ok.mean()) if len(d) else 0.0, float(np.sqrt(np.mean(d[ok] ** 2))) if ok.any() else float("inf")


def accept(reg: Registration, cfg: RegisterConfig, what: str) -> Registration:
    if reg.fitness < cfg.min_fitness or reg.rmse > cfg.max_rmse:
        raise RegistrationError(
            f"cannot register {what}: after {reg.method} only {100 * reg.fitness:.0f}% of the recording's depth "
            f"points lie within {cfg.scales[-1][1]:.2f} m of the map's surface (need {100 * cfg.min_fitness:.0f}%), "
            f"residual (inlier RMSE) {reg.rmse:.3f} m (at most {cfg.max_rmse:.3f} m); is it the same home? "
            "Give a rough transform with --transform to start from")
    return reg
