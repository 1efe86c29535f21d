"""Reader for ScanNet's exported frames (the ``SensReader`` export of a ``.sens`` file).

::

    SRC/color/0.jpg                 colour, 1296x968 in ScanNet
    SRC/depth/0.png                 16-bit depth, ``depth_scale`` (1000) units per metre, 640x480
    SRC/pose/0.txt                  4x4 camera-to-world (rows), OpenCV camera axes; ``-inf`` where
                                    tracking was lost (those frames are skipped and counted)
    SRC/intrinsic/intrinsic_depth.txt, intrinsic_color.txt   4x4 matrices, the pinhole in the top-left 3x3

Colour and depth are taken as one camera (ScanNet registers them: its depth extrinsic is the
identity up to calibration): frames are written at the depth camera's resolution and intrinsics,
the colour resampled into them.
"""

from __future__ import annotations

from pathlib import Path

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics
from capnav.io.folder import FolderReader, FrameFiles, numbered, read_matrix, rigid_or_reason
from capnav.io.intrinsics import image_size

DEPTH_SCALE = 1000.0
FPS = 30.0


def _k(path: Path, size: tuple[int, int]) -> Intrinsics:
    M = read_matrix(path, 4, 4, "intrinsics") if path.is_file() else None
    if M is None:
        raise InputError(f"missing intrinsics file {path}")
    return Intrinsics.from_matrix(M[:3, :3], *size)


class ScannetReader(FolderReader):
    """ScanNet exported frames, written at the depth resolution."""

    kind = "scannet"

    def __init__(self, root: str | Path, intrinsics: str | Path | Intrinsics | None = None,
                 depth_scale: float = DEPTH_SCALE, fps: float = FPS) -> None:
        root = Path(root)
        colour = numbered(root / "color", (".jpg", ".jpeg", ".png"))
        depth = numbered(root / "depth", (".png",))
        if not colour or not depth:
            raise InputError(f"{root}: color/ and depth/ need numbered images ({len(colour)} colour, "
                             f"{len(depth)} depth)")
        order = sorted(colour)
        d_size = image_size(depth[min(depth)])
        c_size = image_size(colour[order[0]])
        if isinstance(intrinsics, Intrinsics):
            Kd, Kc, k_src = intrinsics, intrinsics.scaled(*c_size), "given"
        elif intrinsics is not None:
            raise InputError("ScanNet keeps its intrinsics in intrinsic/; --intrinsics is not taken for this layout")
        else:
            Kd = _k(root / "intrinsic" / "intrinsic_depth.txt", d_size)
            cpath = root / "intrinsic" / "intrinsic_color.txt"
            Kc = _k(cpath, c_size) if cpath.is_file() else Kd.scaled(*c_size)
            k_src = str(root / "intrinsic")
        files = []
        for k in order:
            pose = root / "pose" / f"{colour[k].stem}.txt"
            T, why = None, f"missing pose file {pose}"
            if pose.is_file():
                T, why = rigid_or_reason(read_matrix(pose, 4, 4, "pose"), str(pose))
            files.append(FrameFiles(colour[k].name, k, k / fps, colour[k], depth.get(k), T, why))
        super().__init__(root, Kd, k_src, files, depth_scale,
                         {"colour_images": len(colour), "depth_images": len(depth), "fps": fps},
                         colour_K=Kc, depth_K=Kd)
