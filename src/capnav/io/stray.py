"""Reader for Stray Scanner's iPhone / iPad captures (LiDAR depth and ARKit poses).

::

    SRC/rgb.mp4                 colour video (1920x1440 on recent iPhones), one frame per depth image;
                                or SRC/rgb/000000.jpg|png frames
    SRC/depth/000000.png        16-bit depth, ``depth_scale`` (1000) units per metre, 256x192
    SRC/confidence/000000.png   0, 1, 2 per depth pixel (higher is surer); optional
    SRC/camera_matrix.csv       3x3 pinhole matrix of the colour images, comma separated
    SRC/odometry.csv            header, then "timestamp, frame, x, y, z, qx, qy, qz, qw" per frame:
                                the camera-to-world pose in ARKit's world (y up, gravity aligned)

The camera axes are read as OpenCV's (x right, y down, z forward), as Stray's own tools read them;
``camera_axes="opengl"`` reads them as ARKit's native ones (y up, z backwards). The import's
reprojection check refuses a recording that fits the other reading better. Frames are written at
the colour's field of view, at most ``max_width`` wide: the colour is resampled and the depth
upsampled (nearest neighbour, so no depth is mixed across an edge). Depth pixels under
``min_confidence`` are dropped. The video needs OpenCV (``pip install 'capnav[coco]'``).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, pip_hint
from capnav.core.geometry import Intrinsics
from capnav.io.assoc import poses_from_quat
from capnav.io.consistency import GL
from capnav.io.depth_formats import read_png16
from capnav.io.folder import FolderReader, FrameFiles, numbered, read_matrix, resample
from capnav.io.importer import PlannedFrame
from capnav.io.intrinsics import image_size

DEPTH_SCALE = 1000.0
MAX_WIDTH = 640


def read_odometry(path: Path) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """Frame numbers, timestamps and poses (N, 4, 4) of ``odometry.csv``; errors name the line."""
    try:
        lines = path.read_text(errors="replace").splitlines()
    except FileNotFoundError:
        raise InputError(f"missing pose file: {path}") from None
    rows, names = [], []
    for ln, line in enumerate(lines, start=1):
        s = line.strip()
        if not s or (ln == 1 and not s[0].isdigit() and s[0] not in "-+."):
            continue  # the header
        parts = [p.strip() for p in s.split(",")]
        if len(parts) != 9:
            raise InputError(f"{path} line {ln}: expected 9 comma-separated fields "
                             f"(timestamp, frame, x, y, z, qx, qy, qz, qw), got {len(parts)}")
        try:
            rows.append([float(p) for p in parts])
        except ValueError:
            raise InputError(f"{path} line {ln}: not a number in {s[:80]!r}") from None
        names.append(f"{path} line {ln}")
    if not rows:
        raise InputError(f"{path} lists no poses")
    a = np.asarray(rows, dtype=np.float64)
    return a[:, 1].astype(np.int64), a[:, 0], poses_from_quat(a[:, 0], a[:, 2:5], a[:, 5:9], names)


class StrayReader(FolderReader):
    """A Stray Scanner capture, frames in frame order, at the colour's field of view."""

    kind = "stray"

    def __init__(self, root: str | Path, intrinsics: str | Path | Intrinsics | None = None,
                 depth_scale: float = DEPTH_SCALE, min_confidence: int = 1, camera_axes: str = "opencv",
                 max_width: int = MAX_WIDTH) -> None:
        root = Path(root)
        if camera_axes not in ("opencv", "opengl"):
            raise InputError(f"--camera-axes must be opencv or opengl, got {camera_axes!r}")
        if min_confidence not in (0, 1, 2):
            raise InputError(f"--min-confidence must be 0, 1 or 2, got {min_confidence}")
        depth = numbered(root / "depth", (".png",))
        if not depth:
            raise InputError(f"{root / 'depth'}: no numbered 16-bit .png depth images")
        self.confidence = numbered(root / "confidence", (".png",))
        self.min_confidence = min_confidence
        frames_dir = next((root / d for d in ("rgb", "color", "frames") if (root / d).is_dir()), None)
        video = root / "rgb.mp4"
        if frames_dir is not None:
            colour: dict[int, Any] = numbered(frames_dir, (".jpg", ".jpeg", ".png"))
            c_size = image_size(colour[min(colour)]) if colour else (0, 0)
            self.video: Path | None = None
        elif video.is_file():
            self.video = video
            c_size, count = self._video_info(video)
            colour = {k: k for k in range(count)}
        else:
            raise InputError(f"{root}: no rgb.mp4 and no rgb/ frames folder")
        if not colour:
            raise InputError(f"{root}: no colour frames")
        if isinstance(intrinsics, Intrinsics):
            Kc, k_src = intrinsics, "given"
        else:
            kpath = Path(intrinsics) if intrinsics is not None else root / "camera_matrix.csv"
            Kc = Intrinsics.from_matrix(read_matrix(kpath, 3, 3, "camera matrix", sep=","), *c_size)
            k_src = str(kpath)
        d_size = image_size(depth[min(depth)])
        out_w = min(max_width, Kc.width)
        K = Kc.scaled(out_w, round(Kc.height * out_w / Kc.width))
        ids, stamps, poses = read_odometry(root / "odometry.csv")
        if camera_axes == "opengl":
            poses = poses @ GL
        by_frame = {int(k): (float(t), T) for k, t, T in zip(ids, stamps, poses, strict=True)}
        files = []
        for k in sorted(colour):
            t, T = by_frame.get(k, (float("nan"), None))
            why = "" if T is not None else f"odometry.csv has no line for frame {k} ({len(ids)} poses)"
            name = colour[k].name if isinstance(colour[k], Path) else f"rgb.mp4 frame {k}"
            files.append(FrameFiles(name, k, t if np.isfinite(t) else k / 60.0, colour[k], depth.get(k), T, why))
        super().__init__(root, K, k_src, files, depth_scale,
                         {"colour": "rgb.mp4" if self.video else str(frames_dir), "poses": len(ids),
                          "depth_images": len(depth), "confidence_images": len(self.confidence),
                          "min_confidence": min_confidence, "camera_axes": camera_axes},
                         colour_K=Kc, depth_K=Kc.scaled(*d_size))

    @staticmethod
    def _video_info(video: Path) -> tuple[tuple[int, int], int]:
        cv2 = _cv2()
        cap = cv2.VideoCapture(str(video))
        try:
            if not cap.isOpened():
                raise InputError(f"cannot open the video {video} (OpenCV could not decode it)")
            w, h = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
            n = int(cap.get(cv2.CAP_PROP_FRAME_COUNT))
        finally:
            cap.release()
        if w <= 0 or h <= 0 or n <= 0:
            raise InputError(f"{video}: no frames (OpenCV reads {w}x{h}, {n} frames)")
        return (w, h), n

    def read_depth(self, path: Path) -> NDArray[np.float32]:
        raw = read_png16(path)
        k = int(path.stem) if path.stem.isdigit() else -1
        if self.min_confidence > 0 and k in self.confidence:
            conf = _grey(self.confidence[k])
            if conf.shape == raw.shape:
                raw = np.where(conf >= self.min_confidence, raw, 0).astype(np.uint16)
        raw = resample(raw, self.depth_K, self.K, nearest=True)
        return (raw.astype(np.float32) / np.float32(self.depth_scale)).astype(np.float32)

    def load(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.uint8],
                                                                NDArray[np.float32]]]:
        """Frames from the folder as any layout's, or from the video decoded once in order."""
        if self.video is None:
            yield from super().load(frames)
            return
        cv2 = _cv2()
        want = {int(f.rgb): f for f in frames}
        cap = cv2.VideoCapture(str(self.video))
        try:
            k = 0
            while want and k <= max(want):
                ok, bgr = cap.read()
                if not ok:
                    break
                f = want.pop(k, None)
                k += 1
                if f is None:
                    continue
                try:
                    depth = self.read_depth(f.depth)
                except InputError as e:
                    self.skipped.add(f.name, f.timestamp, "unreadable image", str(e))
                    continue
                rgb = np.ascontiguousarray(bgr[:, :, ::-1])
                yield f, resample(rgb, self.colour_K, self.K, nearest=False), depth
        finally:
            cap.release()
        for f in want.values():
            self.skipped.add(f.name, f.timestamp, "unreadable image", f"{self.video} ends before frame {f.rgb}")


def _grey(path: Path) -> NDArray[np.uint8]:
    from PIL import Image

    try:
        with Image.open(path) as im:
            return np.asarray(im.convert("L"), dtype=np.uint8)
    except (OSError, SyntaxError, ValueError) as e:
        raise InputError(f"corrupt confidence image {path}: {e}") from None


def _cv2() -> Any:
    try:
        import cv2
    except ImportError:
        raise InputError(f"reading rgb.mp4 needs OpenCV: {pip_hint('capnav[coco]')} (or opencv-python-headless), "
                         "or extract the video to SRC/rgb/000000.png ...") from None
    return cv2
