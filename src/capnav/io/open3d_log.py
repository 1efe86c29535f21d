"""Reader for the Open3D / Redwood reconstruction-system folder.

::

    SRC/image/00000.jpg     colour (``color/`` also accepted), jpg or png, numbered
    SRC/depth/00000.png     16-bit depth, ``depth_scale`` (1000) units per metre, 0 = no reading
    SRC/trajectory.log      per frame a line "i j k" then four rows of the 4x4 camera-to-world
                            matrix (Open3D's PinholeCameraTrajectory log), OpenCV camera axes
    SRC/camera_intrinsic.json   optional, Open3D PinholeCameraIntrinsic JSON (else PrimeSense 525/319.5/239.5)

The first number of a log entry's "i j k" line is the frame it belongs to (Open3D writes
``i i i+1`` when it saves a trajectory); entries are otherwise taken in order. The log's world is
whatever the tracker chose (often the first camera's frame, so up is that camera's -y): the
importer finds up from the floor. There are no timestamps; frames are ``1 / fps`` apart.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics
from capnav.io.folder import FolderReader, FrameFiles, numbered, rigid_or_reason
from capnav.io.intrinsics import PRIMESENSE, image_size, read_json

COLOUR_DIRS = ("image", "color", "rgb")
INTRINSIC_FILES = ("camera_intrinsic.json", "intrinsic.json", "intrinsics.json")
DEPTH_SCALE = 1000.0
FPS = 30.0


def read_log(path: Path) -> list[tuple[int, NDArray[np.float64], int]]:
    """Entries of a trajectory log: ``(frame, T, line)`` with ``line`` the entry's first line number."""
    try:
        lines = [(ln, s.split()) for ln, s in enumerate(path.read_text(errors="replace").splitlines(), start=1)
                 if s.strip()]
    except FileNotFoundError:
        raise InputError(f"missing pose file: {path} (the Open3D layout keeps the camera poses there)") from None
    if len(lines) % 5:
        raise InputError(f"{path}: {len(lines)} non-empty lines; a trajectory log has 5 per pose "
                         "(an 'i j k' line and 4 matrix rows)")
    out = []
    for b in range(0, len(lines), 5):
        ln, head = lines[b]
        try:
            frame = int(head[0])
            rows = [[float(v) for v in lines[b + r][1]] for r in range(1, 5)]
        except (ValueError, IndexError):
            raise InputError(f"{path} line {ln}: expected an 'i j k' line and four rows of 4 numbers") from None
        if len(head) != 3 or any(len(r) != 4 for r in rows):
            raise InputError(f"{path} line {ln}: expected an 'i j k' line and four rows of 4 numbers")
        out.append((frame, np.array(rows, dtype=np.float64), ln))
    return out


def log_text(poses: list[NDArray[np.float64]]) -> str:
    """The text of a trajectory log for ``poses`` (camera-to-world), as Open3D writes it."""
    out = []
    for i, T in enumerate(poses):
        out.append(f"{i} {i} {i + 1}")
        out += [" ".join(f"{v:.8f}" for v in row) for row in np.asarray(T, dtype=np.float64)]
    return "\n".join(out) + "\n"


def find_colour_dir(root: Path) -> Path | None:
    return next((root / d for d in COLOUR_DIRS if (root / d).is_dir()), None)


def find_log(root: Path) -> Path | None:
    if (root / "trajectory.log").is_file():
        return root / "trajectory.log"
    logs = sorted(root.glob("*.log"))
    return logs[0] if len(logs) == 1 else None


class Open3dReader(FolderReader):
    """An Open3D reconstruction-system folder as frames in source order."""

    kind = "open3d"

    def __init__(self, root: str | Path, intrinsics: str | Path | Intrinsics | None = None,
                 depth_scale: float = DEPTH_SCALE, fps: float = FPS, trajectory: str | Path | None = None) -> None:
        root = Path(root)
        if not root.is_dir():
            raise InputError(f"Open3D folder not found: {root}")
        if not (fps > 0 and np.isfinite(fps)):
            raise InputError(f"--fps must be > 0, got {fps}")
        cdir = find_colour_dir(root)
        if cdir is None:
            raise InputError(f"{root}: no colour folder ({', '.join(d + '/' for d in COLOUR_DIRS)})")
        colour = numbered(cdir, (".jpg", ".jpeg", ".png"))
        depth = numbered(root / "depth", (".png",))
        if not colour:
            raise InputError(f"{cdir}: no numbered .jpg/.png images")
        if not depth:
            raise InputError(f"{root / 'depth'}: no numbered 16-bit .png depth images")
        log = Path(trajectory) if trajectory is not None else find_log(root)
        if log is None:
            raise InputError(f"missing pose file: {root / 'trajectory.log'} (the Open3D layout keeps the camera "
                             "poses there; pass --trajectory FILE.log if it has another name)")
        entries = read_log(log)
        order = sorted(colour)
        by_frame = self._assign(entries, order, log)
        K, k_src = self._intrinsics(intrinsics, root, colour[order[0]])
        files = []
        for k in order:
            T, why = (None, f"{log.name} has no entry for it ({len(entries)} poses for {len(order)} images)")
            if k in by_frame:
                T, why = rigid_or_reason(*by_frame[k])
            files.append(FrameFiles(colour[k].name, k, k / fps, colour[k], depth.get(k), T, why))
        super().__init__(root, K, k_src, files, depth_scale,
                         {"trajectory": str(log), "poses": len(entries), "colour_images": len(colour),
                          "depth_images": len(depth), "fps": fps})

    @staticmethod
    def _assign(entries: list[tuple[int, NDArray[np.float64], int]], order: list[int],
                log: Path) -> dict[int, tuple[NDArray[np.float64], str]]:
        """Image number -> (pose, where): by the entries' frame numbers when they name distinct images,
        else the k-th entry for the k-th image (Open3D's own reading)."""
        frames = [f for f, _, _ in entries]
        if len(set(frames)) == len(frames) and set(frames) <= set(order):
            return {f: (T, f"{log} line {ln}") for f, T, ln in entries}
        if len(entries) > len(order):
            raise InputError(f"{log}: {len(entries)} poses for {len(order)} colour images, and the entries' frame "
                             "numbers do not name the images; which pose belongs to which image is unknown")
        return {order[i]: (T, f"{log} line {ln}") for i, (_, T, ln) in enumerate(entries)}

    @staticmethod
    def _intrinsics(spec: str | Path | Intrinsics | None, root: Path, first: Path) -> tuple[Intrinsics, str]:
        if isinstance(spec, Intrinsics):
            return spec, "given"
        size = image_size(first)
        if spec is not None:
            return read_json(Path(spec), size), str(spec)
        for name in INTRINSIC_FILES:
            if (root / name).is_file():
                return read_json(root / name, size), str(root / name)
        if size != (PRIMESENSE.width, PRIMESENSE.height):
            raise InputError(f"{root}: no intrinsics file ({', '.join(INTRINSIC_FILES)}) and the images are "
                             f"{size[0]}x{size[1]}, not the PrimeSense default's 640x480; pass --intrinsics FILE.json")
        return PRIMESENSE, "PrimeSense default (no intrinsics file in the folder)"
