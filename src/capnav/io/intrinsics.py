"""Camera intrinsics as recordings store them: JSON files (CapNav's and Open3D's) and text matrices.

CapNav's own form is ``{"fx", "fy", "cx", "cy"[, "width", "height"]}``. Open3D's
``PinholeCameraIntrinsic`` JSON is ``{"width", "height", "intrinsic_matrix": [9 numbers]}`` with
the matrix stored column by column (Eigen's order: ``[fx, 0, 0, 0, fy, 0, cx, cy, 1]``); a
row-major list is recognised too (its last row is ``0 0 1``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics

#: Open3D's ``PinholeCameraIntrinsicParameters.PrimeSenseDefault`` (640x480), the camera its
#: reconstruction system assumes when no intrinsics file is given, and the one ICL-NUIM renders.
PRIMESENSE = Intrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480)


def matrix_3x3(values: list[float] | NDArray[np.floating], where: str) -> NDArray[np.float64]:
    """A pinhole matrix from 9 numbers in either order (the one whose last row reads ``0 0 1``)."""
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if v.size != 9 or not np.isfinite(v).all():
        raise InputError(f"{where}: an intrinsic matrix needs 9 finite numbers, got {v.size}")
    M = v.reshape(3, 3)
    if np.allclose(M[2], [0, 0, 1]):
        return M
    if np.allclose(M[:, 2], [0, 0, 1]):  # stored column by column
        return M.T
    raise InputError(f"{where}: not a pinhole matrix (no row or column reads 0 0 1): {v.tolist()}")


def from_json(d: Any, where: str, size: tuple[int, int] | None) -> Intrinsics:
    """Intrinsics from a parsed JSON object of either form; ``size`` (w, h) fills a missing image size."""
    if not isinstance(d, dict):
        raise InputError(f"intrinsics file {where}: need a JSON object")
    try:
        if "intrinsic_matrix" in d:
            M = matrix_3x3(d["intrinsic_matrix"], where)
            fx, fy, cx, cy = M[0, 0], M[1, 1], M[0, 2], M[1, 2]
        else:
            fx, fy, cx, cy = (float(d[k]) for k in ("fx", "fy", "cx", "cy"))
        has = "width" in d and "height" in d
        wh = (int(d["width"]), int(d["height"])) if has else size
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"intrinsics file {where}: need fx, fy, cx, cy or intrinsic_matrix ({e!r})") from None
    if wh is None:
        raise InputError(f"intrinsics file {where}: needs width and height")
    return Intrinsics(float(fx), float(fy), float(cx), float(cy), *wh)


def read_json(path: Path, size: tuple[int, int] | None = None) -> Intrinsics:
    """Intrinsics from a JSON file (see the module docstring)."""
    try:
        d = json.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"intrinsics file not found: {path}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise InputError(f"intrinsics file {path}: not JSON ({e})") from None
    return from_json(d, str(path), size)


def to_open3d_json(K: Intrinsics) -> dict[str, Any]:
    """Open3D's ``PinholeCameraIntrinsic`` JSON (column-major matrix) for ``K``."""
    return {"width": K.width, "height": K.height,
            "intrinsic_matrix": [K.fx, 0.0, 0.0, 0.0, K.fy, 0.0, K.cx, K.cy, 1.0]}


def image_size(path: Path) -> tuple[int, int]:
    """``(width, height)`` of an image file without decoding its pixels."""
    try:
        with Image.open(path) as im:
            return int(im.size[0]), int(im.size[1])
    except FileNotFoundError:
        raise InputError(f"missing image {path}") from None
    except (OSError, SyntaxError, ValueError) as e:
        raise InputError(f"corrupt image {path}: {e}") from None


def check_fit(K: Intrinsics, k_src: str, images: list[Path], what: str) -> None:
    """Refuse intrinsics that cannot belong to the first readable of ``images`` (a few are tried; an
    unreadable image is the per-frame skip's business): another size, or a principal point outside
    the image (intrinsics of another camera or resolution, read by mistake)."""
    for p in images[:5]:
        try:
            w, h = image_size(p)
            break
        except InputError:
            continue
    else:
        return
    what = f"{what} {p}"
    if (K.width, K.height) != (w, h):
        raise InputError(f"intrinsics ({k_src}) are for {K.width}x{K.height} but {what} is {w}x{h}; "
                         "give the intrinsics of this image size")
    if not (0 < K.cx < w and 0 < K.cy < h):
        raise InputError(f"intrinsics ({k_src}) put the principal point at ({K.cx:g}, {K.cy:g}), outside "
                         f"the {w}x{h} image of {what}; are they for another resolution?")
