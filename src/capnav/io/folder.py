"""What the frame-per-file layouts share (Open3D, 3DMatch, ScanNet, Stray Scanner).

These layouts store one colour image, one depth image and one pose per frame, matched by the
frame's number rather than by time, so a reader only has to list its files: ``FolderReader``
turns that list into ``PlannedFrame``s (in source order, with each frame's source index and
timestamp), counts frames without a depth image or a pose, checks the intrinsics against the first
images, and loads the images (resampled to one camera when a layout stores colour and depth at two
resolutions, like ScanNet and Stray Scanner).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.errors import InputError, PoseError
from capnav.core.geometry import Intrinsics, check_pose
from capnav.io.assoc import SkipLog
from capnav.io.depth_formats import read_png16
from capnav.io.importer import PlannedFrame
from capnav.io.intrinsics import check_fit
from capnav.io.tum import read_rgb


@dataclass(frozen=True)
class FrameFiles:
    """One frame of a folder layout as listed: files, its number in the source, and its pose (or why none)."""

    name: str
    source_index: int
    timestamp: float
    rgb: Path | int  # a file, or a frame of a video
    depth: Path | None  # None: no depth image of this number
    T_wc: NDArray[np.float64] | None
    why_no_pose: str = ""


def numbered(folder: Path, suffixes: tuple[str, ...], pattern: str = "") -> dict[int, Path]:
    """Files of ``folder`` with one of ``suffixes``, keyed by the (last) integer in their name."""
    import re

    out: dict[int, Path] = {}
    rx = re.compile(pattern or r"(\d+)(?!.*\d)")
    for p in folder.iterdir() if folder.is_dir() else ():
        if p.suffix.lower() in suffixes and p.is_file():
            m = rx.search(p.name)
            if m is not None:
                k = int(m.group(1))
                if k in out:
                    raise InputError(f"{folder}: two files for frame {k}: {out[k].name} and {p.name}")
                out[k] = p
    return out


def read_matrix(path: Path, rows: int, cols: int, what: str, sep: str | None = None) -> NDArray[np.float64]:
    """A ``rows x cols`` matrix of numbers from a text file (whitespace or ``sep`` separated)."""
    try:
        text = path.read_text(errors="replace")
    except FileNotFoundError:
        raise InputError(f"missing {what} file: {path}") from None
    except OSError as e:
        raise InputError(f"cannot read {what} file {path}: {e.strerror or e}") from None
    try:
        vals = [float(v) for v in text.replace(sep or " ", " ").split()]
    except ValueError:
        raise InputError(f"{what} file {path}: not all numbers ({text[:60]!r})") from None
    if len(vals) != rows * cols:
        raise InputError(f"{what} file {path}: expected {rows}x{cols} numbers, got {len(vals)}")
    return np.asarray(vals, dtype=np.float64).reshape(rows, cols)


def rigid_or_reason(T: NDArray[np.float64], where: str) -> tuple[NDArray[np.float64] | None, str]:
    """``(T, "")`` for a rigid pose, ``(None, why)`` for an invalid one (ScanNet marks lost tracking with -inf)."""
    try:
        return check_pose(T, frame=where), ""
    except PoseError as e:
        return None, e.reason


def resample(img: NDArray[Any], K_in: Intrinsics, K_out: Intrinsics, nearest: bool) -> NDArray[Any]:
    """``img`` (taken with ``K_in``) as the same camera with ``K_out`` would see it: the two differ by a
    scale and an offset per axis (same centre of projection), so each output pixel samples the input
    at ``K_in K_out^-1 (u, v, 1)``; nearest for depth (no depth mixed across an edge), bilinear for colour."""
    ax, ay = K_in.fx / K_out.fx, K_in.fy / K_out.fy
    u = np.arange(K_out.width) * ax + (K_in.cx - ax * K_out.cx)
    v = np.arange(K_out.height) * ay + (K_in.cy - ay * K_out.cy)
    if nearest:
        ui, vi = np.rint(u).astype(np.intp), np.rint(v).astype(np.intp)
        ok = (ui >= 0) & (ui < img.shape[1]), (vi >= 0) & (vi < img.shape[0])
        out = img[np.clip(vi, 0, img.shape[0] - 1)][:, np.clip(ui, 0, img.shape[1] - 1)]
        return np.where(ok[1][:, None] & ok[0][None, :], out, 0).astype(img.dtype)
    # PIL samples at pixel centres (x + 0.5): shift the offsets accordingly
    c = K_in.cx - ax * K_out.cx + 0.5 - 0.5 * ax
    f = K_in.cy - ay * K_out.cy + 0.5 - 0.5 * ay
    im = Image.fromarray(img).transform((K_out.width, K_out.height), Image.Transform.AFFINE,
                                        (ax, 0.0, c, 0.0, ay, f), resample=Image.Resampling.BILINEAR)
    return np.asarray(im, dtype=img.dtype)


class FolderReader:
    """A frame-per-file recording; subclasses list their frames and intrinsics, this does the rest."""

    kind = "folder"

    def __init__(self, root: Path, K: Intrinsics, k_src: str, files: list[FrameFiles], depth_scale: float,
                 meta: dict[str, Any], colour_K: Intrinsics | None = None, depth_K: Intrinsics | None = None,
                 invalid_depth: int | None = None) -> None:
        """``K`` is the camera of the frames written; ``colour_K`` / ``depth_K`` those of the stored
        images when they differ (ScanNet, Stray Scanner keep colour and depth at two resolutions):
        each image is then resampled to ``K``. ``invalid_depth`` is a raw value meaning no reading
        besides 0 (7-Scenes writes 65535)."""
        if not (depth_scale > 0 and np.isfinite(depth_scale)):
            raise InputError(f"--depth-scale must be a positive number, got {depth_scale}")
        if not files:
            raise InputError(f"{root}: no frames found")
        self.path, self.K, self.depth_scale = root, K, float(depth_scale)
        self.colour_K, self.depth_K = colour_K or K, depth_K or K
        self.invalid_depth = invalid_depth
        files = sorted(files, key=lambda f: f.source_index)
        paired = [f for f in files if f.depth is not None]
        if not paired:
            raise InputError(f"{root}: no colour image has a depth image of the same number")
        check_fit(self.depth_K, k_src, [f.depth for f in paired[:5] if f.depth], "the depth image")
        check_fit(self.colour_K, k_src, [f.rgb for f in paired[:5] if isinstance(f.rgb, Path)], "the colour image")
        self.skipped = SkipLog()
        self.frames: list[PlannedFrame] = []
        for f in files:
            if f.depth is None:
                self.skipped.add(f.name, f.timestamp, "no depth image", f"no depth image numbered {f.source_index}")
            elif f.T_wc is None:
                self.skipped.add(f.name, f.timestamp, "no pose", f.why_no_pose)
            else:
                self.frames.append(PlannedFrame(f.name, f.timestamp, f.T_wc, f.rgb, f.depth, f.source_index))
        if not self.frames:
            ex = self.skipped.skips[0]
            raise InputError(f"{root}: no frame has both a depth image and a pose ({len(files)} colour images; "
                             f"the first, {ex.name}: {ex.reason}, {ex.detail})")
        self.meta: dict[str, Any] = {"intrinsics_source": k_src, "depth_scale_in": self.depth_scale, **meta}
        if self.colour_K != K:
            self.meta["colour_intrinsics_in"] = self.colour_K.to_dict()
        if self.depth_K != K:
            self.meta["depth_intrinsics_in"] = self.depth_K.to_dict()

    def read_depth(self, path: Path) -> NDArray[np.float32]:
        raw = read_png16(path)
        if self.invalid_depth is not None:
            raw = np.where(raw == self.invalid_depth, 0, raw).astype(np.uint16)
        if self.depth_K != self.K:
            raw = resample(raw, self.depth_K, self.K, nearest=True)
        return (raw.astype(np.float32) / np.float32(self.depth_scale)).astype(np.float32)

    def read_colour(self, path: Path) -> NDArray[np.uint8]:
        rgb = read_rgb(path)
        return resample(rgb, self.colour_K, self.K, nearest=False) if self.colour_K != self.K else rgb

    def load_depths(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.float32]]]:
        """Depth images for the floor fit; unreadable ones are left out here (``load`` counts them)."""
        for f in frames:
            try:
                yield f, self.read_depth(f.depth)
            except InputError:
                continue

    def load(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.uint8],
                                                                NDArray[np.float32]]]:
        """Colour and depth per frame; a missing or corrupt image skips its frame, counted with the reason."""
        for f in frames:
            try:
                rgb, depth = self.read_colour(f.rgb), self.read_depth(f.depth)
            except InputError as e:
                self.skipped.add(f.name, f.timestamp, "unreadable image", str(e))
                continue
            yield f, rgb, depth
