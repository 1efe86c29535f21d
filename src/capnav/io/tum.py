"""Reader for the TUM RGB-D benchmark layout (Sturm et al., IROS 2012).

::

    SRC/rgb.txt           "timestamp rgb/<stamp>.png" per line, '#' comments
    SRC/depth.txt         "timestamp depth/<stamp>.png"
    SRC/groundtruth.txt   "timestamp tx ty tz qx qy qz qw": camera optical frame -> world
    SRC/rgb/*.png         8-bit colour
    SRC/depth/*.png       16-bit depth, ``depth_scale`` (5000) units per metre, 0 = no reading

Colour images are associated with the mutually nearest depth image within ``max_dt`` and the
ground-truth pose interpolated at the colour stamp (``capnav.io.assoc``).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics
from capnav.io.assoc import PoseTrack, SkipLog, check_gap, match_nearest, poses_from_quat
from capnav.io.depth_formats import read_png16
from capnav.io.importer import PlannedFrame
from capnav.io.intrinsics import check_fit, image_size, read_json

#: Published calibration of the three Kinects of the benchmark (640x480), from the dataset's
#: "File Formats" page, section "Intrinsic Camera Calibration of the Kinect":
#: https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats
#: (the page also lists lens distortion for fr1/fr2; like most TUM users we do not undistort)
FREIBURG: dict[str, Intrinsics] = {
    "fr1": Intrinsics(fx=517.3, fy=516.5, cx=318.6, cy=255.3, width=640, height=480),
    "fr2": Intrinsics(fx=520.9, fy=521.0, cx=325.1, cy=249.7, width=640, height=480),
    "fr3": Intrinsics(fx=535.4, fy=539.2, cx=320.1, cy=247.6, width=640, height=480),
}
DEPTH_SCALE = 5000.0  # TUM depth PNG units per metre
CAM_JSON = "cam.json"  # intrinsics beside rgb.txt, read when --intrinsics is not given
MAX_DT = 0.02  # seconds, as the benchmark's associate.py
MAX_POSE_GAP = 0.5  # seconds between the ground-truth stamps around a frame


def read_list(path: Path, columns: int, what: str) -> list[list[str]]:
    """Non-comment lines of a TUM text file split into ``columns`` fields; errors name the file and line."""
    if not path.is_file():
        raise InputError(f"missing {what} file: {path}")
    rows = []
    for ln, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        parts = s.split()
        if len(parts) != columns:
            raise InputError(f"{path} line {ln}: expected {columns} fields, got {len(parts)}: {s[:80]!r}")
        try:
            float(parts[0])
            if columns > 2:
                [float(v) for v in parts[1:]]
        except ValueError:
            raise InputError(f"{path} line {ln}: not a number in {s[:80]!r}") from None
        rows.append([*parts, str(ln)])
    return rows


def load_intrinsics(spec: str | Path | Intrinsics | None, root: Path,
                    first_rgb: Path | None = None) -> tuple[Intrinsics, str]:
    """``fr1``/``fr2``/``fr3``, a JSON file (``capnav.io.intrinsics``; without a size the first colour
    image gives it), or None to read ``cam.json`` beside ``rgb.txt``, else take the preset of a folder
    named like ``rgbd_dataset_freiburg2_desk``. Returns the intrinsics and where they came from."""
    if isinstance(spec, Intrinsics):
        return spec, "given"
    if spec is None and (root / CAM_JSON).is_file():
        spec = root / CAM_JSON
    if spec is None:
        m = re.search(r"freiburg([123])", root.resolve().name)
        if m is None:
            raise InputError(f"{root}: cannot tell the camera; pass --intrinsics fr1|fr2|fr3 or a JSON file "
                             '{"fx", "fy", "cx", "cy", "width", "height"}')
        return FREIBURG[f"fr{m.group(1)}"], f"fr{m.group(1)} (from the folder name)"
    key = str(spec).strip().lower()
    if key in FREIBURG:
        return FREIBURG[key], key
    p = Path(spec)
    if not p.is_file():
        raise InputError(f"--intrinsics must be fr1, fr2, fr3 or a JSON file; {p} not found")
    size = None
    if first_rgb is not None:
        try:
            size = image_size(first_rgb)
        except InputError:  # its frame is skipped later; the file may still give the size
            pass
    return read_json(p, size), str(p)


def read_rgb(path: Path) -> NDArray[np.uint8]:
    try:
        with Image.open(path) as im:
            return np.asarray(im.convert("RGB"), dtype=np.uint8)
    except FileNotFoundError:
        raise InputError(f"missing colour image {path}") from None
    except (OSError, SyntaxError, ValueError) as e:
        raise InputError(f"corrupt colour image {path}: {e}") from None


def read_depth(path: Path, scale: float) -> NDArray[np.float32]:
    """A 16-bit depth PNG in metres (``scale`` units per metre, TUM's 5000)."""
    return (read_png16(path).astype(np.float32) / np.float32(scale)).astype(np.float32)


class TumReader:
    """A TUM RGB-D sequence as associated frames (``frames``) plus the colour images dropped (``skipped``)."""

    kind = "tum"

    def __init__(self, root: str | Path, intrinsics: str | Path | Intrinsics | None = None,
                 depth_scale: float = DEPTH_SCALE, max_dt: float = MAX_DT, max_pose_gap: float = MAX_POSE_GAP,
                 groundtruth: str = "groundtruth.txt") -> None:
        self.path = root = Path(root)
        if not root.is_dir():
            raise InputError(f"TUM sequence folder not found: {root}")
        if not (depth_scale > 0 and np.isfinite(depth_scale)):
            raise InputError(f"--depth-scale must be a positive number, got {depth_scale}")
        if not max_dt > 0:
            raise InputError(f"--max-dt must be > 0 s, got {max_dt}")
        check_gap(max_pose_gap)
        self.depth_scale = float(depth_scale)
        rgb = read_list(root / "rgb.txt", 2, "colour list")
        dep = read_list(root / "depth.txt", 2, "depth list")
        gt_path = root / groundtruth
        gt = read_list(gt_path, 8, "ground-truth pose")
        for rows, what in ((rgb, "rgb.txt"), (dep, "depth.txt"), (gt, groundtruth)):
            if not rows:
                raise InputError(f"{root / what} lists nothing")
        missing = [r[1] for r in rgb + dep if not (root / r[1]).is_file()]
        if missing:
            raise InputError(f"{root}: {len(missing)} listed images are missing, e.g. "
                             + ", ".join(str(root / m) for m in missing[:3]))
        self.K, k_src = load_intrinsics(intrinsics, root, root / rgb[0][1])
        check_fit(self.K, k_src, [root / r[1] for r in rgb[:5]], "the colour image")
        check_fit(self.K, k_src, [root / r[1] for r in dep[:5]], "the depth image")
        g = np.array([[float(v) for v in r[:8]] for r in gt])
        track = PoseTrack(g[:, 0], poses_from_quat(g[:, 0], g[:, 1:4], g[:, 4:8],
                                                   [f"{gt_path} line {r[8]}" for r in gt]), str(gt_path))
        t_rgb = np.array([float(r[0]) for r in rgb])
        t_dep = np.array([float(r[0]) for r in dep])
        j, dt = match_nearest(t_rgb, t_dep, max_dt)
        poses, has_pose, why = track.at(t_rgb, max_dt, max_pose_gap)
        self.skipped = SkipLog()
        self.frames: list[PlannedFrame] = []
        for i in np.argsort(t_rgb, kind="stable").tolist():
            name = rgb[i][1]
            if j[i] < 0:
                reason = (f"nearest depth {dt[i] * 1000:.0f} ms away" if dt[i] > max_dt
                          else "its nearest depth image is nearer to another colour image")
                self.skipped.add(name, t_rgb[i], f"no depth within max-dt {max_dt} s", reason)
            elif not has_pose[i]:
                self.skipped.add(name, t_rgb[i], "no pose", why[i])
            else:
                self.frames.append(PlannedFrame(name, float(t_rgb[i]), poses[i], root / name, root / dep[j[i]][1], i))
        self.meta: dict[str, Any] = {"intrinsics_source": k_src, "depth_scale_in": self.depth_scale,
                                     "max_dt": max_dt, "colour_images": len(rgb), "depth_images": len(dep),
                                     "poses": len(track)}

    def load_depths(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.float32]]]:
        """Depth images for the floor fit; unreadable ones are left out here (``load`` counts them)."""
        for f in frames:
            try:
                yield f, read_depth(f.depth, self.depth_scale)
            except InputError:
                continue

    def load(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.uint8],
                                                                NDArray[np.float32]]]:
        """Colour and depth per frame; a frame whose image is missing or corrupt is skipped and
        counted in ``skipped`` with the file and the decoder's complaint, never the whole import."""
        for f in frames:
            try:
                rgb, depth = read_rgb(f.rgb), read_depth(f.depth, self.depth_scale)
            except InputError as e:
                self.skipped.add(f.name, f.timestamp, "unreadable image", str(e))
                continue
            yield f, rgb, depth
