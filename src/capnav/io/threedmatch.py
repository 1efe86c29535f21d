"""Reader for the 3DMatch / 7-Scenes layout.

::

    SCENE/camera-intrinsics.txt            3x3 pinhole matrix (rows)
    SCENE/seq-01/frame-000000.color.png    colour (png or jpg)
    SCENE/seq-01/frame-000000.depth.png    16-bit depth, ``depth_scale`` (1000) units per metre;
                                           0 and 65535 (7-Scenes) = no reading
    SCENE/seq-01/frame-000000.pose.txt     4x4 camera-to-world (rows), OpenCV camera axes

``SRC`` may be the scene (its ``seq-*`` folders are read in name order into one recording: they
share the scene's world) or one sequence folder (the intrinsics then beside it or in its parent).
"""

from __future__ import annotations

import re
from pathlib import Path

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics
from capnav.io.folder import FolderReader, FrameFiles, read_matrix, rigid_or_reason
from capnav.io.intrinsics import image_size, read_json

INTRINSICS = "camera-intrinsics.txt"
DEPTH_SCALE = 1000.0
FPS = 30.0
_FRAME = re.compile(r"^frame-(\d+)\.color\.(png|jpg|jpeg)$", re.IGNORECASE)


def sequence_dirs(root: Path) -> list[Path]:
    """``root`` itself when it holds frames, else its sub-folders that do (in name order)."""
    def has_frames(d: Path) -> bool:
        return d.is_dir() and any(_FRAME.match(p.name) for p in d.iterdir())

    if has_frames(root):
        return [root]
    return sorted(d for d in root.iterdir() if has_frames(d)) if root.is_dir() else []


class ThreeDMatchReader(FolderReader):
    """A 3DMatch scene (or one of its sequences) as frames in sequence and frame order."""

    kind = "3dmatch"

    def __init__(self, root: str | Path, intrinsics: str | Path | Intrinsics | None = None,
                 depth_scale: float = DEPTH_SCALE, fps: float = FPS) -> None:
        root = Path(root)
        seqs = sequence_dirs(root)
        if not seqs:
            raise InputError(f"{root}: no frame-XXXXXX.color.png|jpg files here or in its sub-folders")
        files: list[FrameFiles] = []
        for seq in seqs:
            for p in sorted(p for p in seq.iterdir() if _FRAME.match(p.name)):
                m = _FRAME.match(p.name)
                assert m is not None
                stem = f"frame-{m.group(1)}"
                name = p.name if seq == root else f"{seq.name}/{p.name}"
                n = len(files)
                depth, pose = seq / f"{stem}.depth.png", seq / f"{stem}.pose.txt"
                T, why = None, f"missing pose file {pose}"
                if pose.is_file():
                    T, why = rigid_or_reason(read_matrix(pose, 4, 4, "pose"), str(pose))
                files.append(FrameFiles(name, n, n / fps, p, depth if depth.is_file() else None, T, why))
        first = files[0].rgb
        assert isinstance(first, Path)
        K, k_src = self._intrinsics(intrinsics, root, seqs[0], first)
        super().__init__(root, K, k_src, files, depth_scale,
                         {"sequences": [s.name for s in seqs], "fps": fps}, invalid_depth=65535)

    @staticmethod
    def _intrinsics(spec: str | Path | Intrinsics | None, root: Path, seq: Path,
                    first: Path) -> tuple[Intrinsics, str]:
        if isinstance(spec, Intrinsics):
            return spec, "given"
        size = image_size(first)
        if spec is not None:
            p = Path(spec)
            if p.suffix.lower() == ".json":
                return read_json(p, size), str(p)
            return Intrinsics.from_matrix(read_matrix(p, 3, 3, "intrinsics"), *size), str(p)
        for d in dict.fromkeys((root, seq, seq.parent)):
            if (d / INTRINSICS).is_file():
                p = d / INTRINSICS
                return Intrinsics.from_matrix(read_matrix(p, 3, 3, "intrinsics"), *size), str(p)
        raise InputError(f"{root}: missing intrinsics file {INTRINSICS} (looked in {root}"
                         + (f" and {seq}" if seq != root else "") + "); pass --intrinsics FILE")
