"""Write posed RGB-D frames in the layouts other tools use (TUM, Open3D, 3DMatch, ScanNet).

What ``capnav sim --export`` runs, so every importer can be tried on a recording whose truth is
known. Each writer keeps the intrinsics, depth scale and pose convention as its layout does (see
docs/formats.md); poses are written in the frames' own world (``capnav sim --tilt`` turns it
first, so an importer has to find up by itself).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics

EXPORT_LAYOUTS = ("tum", "open3d", "3dmatch", "scannet")
TUM_T0 = 1.7e9  # s; TUM stamps are Unix times, large enough that float parsing precision matters
SCANNET_COLOUR_SCALE = 2.025  # ScanNet's colour is 1296x968 for 640x480 depth; exports keep that ratio


def _depth_png(depth: NDArray[np.floating], scale: float) -> NDArray[np.uint16]:
    d = np.asarray(depth, dtype=np.float64)
    units = np.where(np.isfinite(d) & (d > 0), np.round(d * scale), 0)
    return np.where(units < 65535.5, units, 0).astype(np.uint16)


def _save(arr: NDArray[np.generic], path: Path) -> None:
    Image.fromarray(arr).save(path)


def _matrix(T: NDArray[np.floating]) -> str:
    return "\n".join(" ".join(f"{v:.9g}" for v in row) for row in np.asarray(T, dtype=np.float64)) + "\n"


def write_tum(frames: Iterable[Frame], K: Intrinsics, out: Path, fps: float = 30.0) -> int:
    """TUM RGB-D: ``rgb/`` and ``depth/`` named by stamp, the three lists, depth at 5000 per metre,
    ground truth as ``t tx ty tz qx qy qz qw`` (camera to world), and ``cam.json`` (intrinsics)."""
    from scipy.spatial.transform import Rotation

    (out / "rgb").mkdir(parents=True)
    (out / "depth").mkdir()
    rgb, dep, gt = ["# color images", "# timestamp filename"], ["# depth maps", "# timestamp filename"], \
        ["# ground truth trajectory", "# timestamp tx ty tz qx qy qz qw"]
    n = 0
    for n, f in enumerate(frames, start=1):
        t = f"{TUM_T0 + (n - 1) / fps:.6f}"
        _save(f.rgb, out / "rgb" / f"{t}.png")
        _save(_depth_png(f.depth, 5000.0), out / "depth" / f"{t}.png")
        rgb.append(f"{t} rgb/{t}.png")
        dep.append(f"{t} depth/{t}.png")
        q = Rotation.from_matrix(f.T_wc[:3, :3]).as_quat()
        gt.append(f"{t} " + " ".join(f"{v:.7f}" for v in (*f.T_wc[:3, 3], *q)))
    for name, lines in (("rgb.txt", rgb), ("depth.txt", dep), ("groundtruth.txt", gt)):
        (out / name).write_text("\n".join(lines) + "\n")
    (out / "cam.json").write_text(json.dumps(K.to_dict()))
    return n


def write_open3d(frames: Iterable[Frame], K: Intrinsics, out: Path) -> int:
    """Open3D reconstruction system: ``image/00000.png``, ``depth/00000.png`` (millimetres),
    ``trajectory.log`` (camera to world) and ``camera_intrinsic.json`` (PinholeCameraIntrinsic)."""
    from capnav.io.intrinsics import to_open3d_json
    from capnav.io.open3d_log import log_text

    (out / "image").mkdir(parents=True)
    (out / "depth").mkdir()
    poses = []
    for i, f in enumerate(frames):
        _save(f.rgb, out / "image" / f"{i:05d}.png")
        _save(_depth_png(f.depth, 1000.0), out / "depth" / f"{i:05d}.png")
        poses.append(f.T_wc)
    (out / "trajectory.log").write_text(log_text(poses))
    (out / "camera_intrinsic.json").write_text(json.dumps(to_open3d_json(K)))
    return len(poses)


def write_3dmatch(frames: Iterable[Frame], K: Intrinsics, out: Path) -> int:
    """3DMatch: ``camera-intrinsics.txt`` (3x3) and ``seq-01/frame-000000.{color.png,depth.png,pose.txt}``
    (depth in millimetres, pose camera to world)."""
    seq = out / "seq-01"
    seq.mkdir(parents=True)
    (out / "camera-intrinsics.txt").write_text(_matrix(K.K))
    n = 0
    for n, f in enumerate(frames, start=1):
        stem = seq / f"frame-{n - 1:06d}"
        _save(f.rgb, stem.with_name(stem.name + ".color.png"))
        _save(_depth_png(f.depth, 1000.0), stem.with_name(stem.name + ".depth.png"))
        stem.with_name(stem.name + ".pose.txt").write_text(_matrix(f.T_wc))
    return n


def write_scannet(frames: Iterable[Frame], K: Intrinsics, out: Path) -> int:
    """ScanNet's export: ``color/0.jpg`` at ScanNet's larger colour resolution (same field of view),
    ``depth/0.png`` (millimetres), ``pose/0.txt`` (camera to world), ``intrinsic/`` (4x4 matrices)."""
    for sub in ("color", "depth", "pose", "intrinsic"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    Kc = K.scaled(round(K.width * SCANNET_COLOUR_SCALE), round(K.height * SCANNET_COLOUR_SCALE))
    for name, k in (("intrinsic_color.txt", Kc), ("intrinsic_depth.txt", K)):
        M = np.eye(4)
        M[:3, :3] = k.K
        (out / "intrinsic" / name).write_text(_matrix(M))
    for name in ("extrinsic_color.txt", "extrinsic_depth.txt"):
        (out / "intrinsic" / name).write_text(_matrix(np.eye(4)))
    n = 0
    for n, f in enumerate(frames, start=1):
        big = Image.fromarray(f.rgb).resize((Kc.width, Kc.height), Image.Resampling.BICUBIC)
        big.save(out / "color" / f"{n - 1}.jpg", quality=95)
        _save(_depth_png(f.depth, 1000.0), out / "depth" / f"{n - 1}.png")
        (out / "pose" / f"{n - 1}.txt").write_text(_matrix(f.T_wc))
    return n


WRITERS: dict[str, Callable[[Iterable[Frame], Intrinsics, Path], int]] = {
    "tum": write_tum, "open3d": write_open3d, "3dmatch": write_3dmatch, "scannet": write_scannet}


def writer(layout: str) -> Callable[[Iterable[Frame], Intrinsics, Path], int]:
    """The writer of ``layout`` (one of ``EXPORT_LAYOUTS``)."""
    if layout not in WRITERS:
        raise InputError(f"--export must be one of {', '.join(EXPORT_LAYOUTS)}, got {layout!r}")
    return WRITERS[layout]


def tilt_matrix(spec: str | tuple[float, float, float] | None) -> NDArray[np.float64]:
    """The recording world's rotation from ``ROLL,PITCH,YAW`` degrees (about x, y, z, applied in that
    order): ``T_wc_recording = W @ T_wc``."""
    from scipy.spatial.transform import Rotation

    W = np.eye(4)
    if spec is None:
        return W
    if isinstance(spec, str):
        try:
            vals = tuple(float(v) for v in spec.split(","))
        except ValueError:
            raise InputError(f"--tilt must be ROLL,PITCH,YAW in degrees, got {spec!r}") from None
    else:
        vals = tuple(float(v) for v in spec)
    if len(vals) != 3 or not np.isfinite(vals).all():
        raise InputError(f"--tilt must be three finite numbers ROLL,PITCH,YAW in degrees, got {spec!r}")
    W[:3, :3] = Rotation.from_euler("xyz", vals, degrees=True).as_matrix()
    return W


def check_export_target(out: Path, overwrite: bool) -> None:
    """``out`` may receive an export: absent, empty, or (with ``overwrite``) a recording of a known layout;
    a folder holding anything else is never replaced."""
    from capnav.core.errors import DatasetError
    from capnav.io.layouts import detect

    if out.exists() and not out.is_dir():
        raise DatasetError(f"{out} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()):
        if not overwrite:
            raise DatasetError(f"{out} is not empty (pass --overwrite to replace it)")
        try:
            detect(out)
        except InputError:
            raise DatasetError(f"{out} holds no recording CapNav wrote; refusing to replace it") from None
