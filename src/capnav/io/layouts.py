"""Which recording layout a folder (or file) is, from the files it holds, and the reader for it.

``capnav import auto SRC`` asks ``detect``; each layout names the files that gave it away, so the
user reads what was recognised. A folder holding at least half of one layout's parts (a recording
copied without its trajectory) is told which of them it lacks; any other folder gets the list of
what was looked for.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from capnav.core.errors import CapNavError, InputError
from capnav.io.open3d_log import COLOUR_DIRS

if TYPE_CHECKING:
    from capnav.io.importer import Recording


@dataclass(frozen=True)
class Layout:
    """A recording layout: its name, what it looks like, its reader, and how a folder shows it.

    A layout told by its files alone lists them as ``parts`` (each with its alternatives) and the
    evidence is those parts when all are there; one that needs to read a file (``meta.json``) or
    to search sequence folders gives its own ``test``.
    """

    name: str
    looks_like: str
    reader: Callable[..., Recording] | None  # keyword options: intrinsics, depth_scale
    #: The files and folders (``name/``) a folder of this layout holds, each with its alternatives;
    #: what ``detect`` compares a folder with when no layout matches whole.
    parts: tuple[tuple[str, ...], ...] = ()
    #: Files named in the evidence when present, not required (TUM's groundtruth.txt).
    extras: tuple[str, ...] = ()
    #: The evidence (or None) when ``parts`` cannot tell it.
    test: Callable[[Path], str | None] | None = None

    def evidence(self, root: Path) -> str | None:
        """What in ``root`` shows this layout, or None when it is not this layout."""
        if self.test is not None:
            return self.test(root)
        if not root.is_dir():
            return None
        has, lacks = self.missing(root)
        if lacks:
            return None
        return ", ".join(has + [e for e in self.extras if _exists(root, e)])

    def missing(self, root: Path) -> tuple[list[str], list[str]]:
        """The parts ``root`` has (the name found) and the ones it lacks (the first alternative)."""
        has: list[str] = []
        lacks: list[str] = []
        for alts in self.parts:
            found = next((a for a in alts if _exists(root, a)), None)
            (has.append(found) if found is not None else lacks.append(alts[0]))
        return has, lacks


def _exists(root: Path, name: str) -> bool:
    if name.endswith("/"):
        return (root / name.rstrip("/")).is_dir()
    if name.startswith("*"):
        return any(root.glob(name))
    return (root / name).is_file()



def _capnav(root: Path) -> str | None:
    if not (root / "meta.json").is_file():
        return None
    try:
        from capnav.core.jsonfile import read_json_object

        if read_json_object(root / "meta.json", "meta.json").get("format") == "capnav-rgbd":
            return "meta.json says capnav-rgbd"
    except CapNavError:  # a broken meta.json is simply not this layout
        return None
    return None



def _rosbag(root: Path) -> str | None:
    if root.is_file() and root.suffix == ".bag":
        return "a .bag file"
    if root.is_dir() and (root / "metadata.yaml").is_file() and any(root.glob("*.db3")) | any(root.glob("*.mcap")):
        return "metadata.yaml and a .db3/.mcap file (ROS2 bag)"
    return None



def _open3d(root: Path) -> str | None:
    from capnav.io.open3d_log import find_colour_dir, find_log

    c, log = find_colour_dir(root), find_log(root)
    if c is None or log is None or not (root / "depth").is_dir():
        return None
    return f"{c.name}/, depth/, {log.name}"


def _3dmatch(root: Path) -> str | None:
    from capnav.io.threedmatch import sequence_dirs

    seqs = sequence_dirs(root)
    if not seqs:
        return None
    where = "" if seqs == [root] else f" in {len(seqs)} sequence folder(s) ({', '.join(s.name for s in seqs[:3])})"
    return f"frame-XXXXXX.color/.depth/.pose files{where}"



def _open(module: str, cls: str) -> Callable[..., Recording]:
    def make(src: Path, **opts: Any) -> Recording:
        import importlib

        reader: Recording = getattr(importlib.import_module(module), cls)(src, **opts)
        return reader
    return make


LAYOUTS: tuple[Layout, ...] = (
    Layout("capnav-rgbd", "meta.json with format capnav-rgbd (already a CapNav dataset)", None, test=_capnav),
    Layout("tum", "rgb.txt, depth.txt, groundtruth.txt", _open("capnav.io.tum", "TumReader"),
           (("rgb.txt",), ("depth.txt",)), extras=("groundtruth.txt",)),
    Layout("rosbag", "a ROS1 .bag file or a ROS2 bag folder", None, test=_rosbag),
    Layout("scannet", "color/, depth/, pose/, intrinsic/ (ScanNet's exported frames)",
           _open("capnav.io.scannet", "ScannetReader"), (("color/",), ("depth/",), ("pose/",), ("intrinsic/",))),
    Layout("open3d", "image/ (or color/), depth/, trajectory.log (Open3D / Redwood)",
           _open("capnav.io.open3d_log", "Open3dReader"),
           (tuple(f"{d}/" for d in COLOUR_DIRS), ("depth/",), ("trajectory.log", "*.log")), test=_open3d),
    Layout("stray", "odometry.csv, camera_matrix.csv, depth/, rgb.mp4 or rgb/ (Stray Scanner)",
           _open("capnav.io.stray", "StrayReader"), (("odometry.csv",), ("camera_matrix.csv",), ("depth/",)),
           extras=("rgb.mp4",)),
    Layout("3dmatch", "frame-XXXXXX.color.png|jpg, .depth.png, .pose.txt, camera-intrinsics.txt",
           _open("capnav.io.threedmatch", "ThreeDMatchReader"), test=_3dmatch),
)


def detect(src: Path) -> tuple[Layout, str]:
    """The layout of ``src`` and the files that show it; an ``InputError`` listing the layouts otherwise."""
    if not src.exists():
        raise InputError(f"recording not found: {src}")
    for lay in LAYOUTS:
        ev = lay.evidence(src) if src.is_dir() or lay.name == "rosbag" else None
        if ev is not None:
            return lay, ev
    near = _nearest(src) if src.is_dir() else None
    if near is not None:
        lay, has, lacks = near
        raise InputError(f"{src} looks like the {lay.name} layout (has {', '.join(has)}) but "
                         f"{' and '.join(lacks)} {'is' if len(lacks) == 1 else 'are'} missing "
                         f"(the {lay.name} layout holds {lay.looks_like})")
    known = "; ".join(f"{lay.name}: {lay.looks_like}" for lay in LAYOUTS)
    raise InputError(f"{src}: not a recording layout CapNav knows. Looked for {known}")


def _nearest(root: Path) -> tuple[Layout, list[str], list[str]] | None:
    """The layout of which ``root`` holds the largest share of parts, when that is at least half."""
    best: tuple[float, int, Layout, list[str], list[str]] | None = None
    for lay in LAYOUTS:
        if not lay.parts:
            continue
        has, lacks = lay.missing(root)
        share = len(has) / len(lay.parts)
        if share >= 0.5 and lacks and (best is None or (share, len(has)) > best[:2]):
            best = (share, len(has), lay, has, lacks)
    return None if best is None else best[2:]


def open_recording(src: Path, **opts: Any) -> tuple[Recording, Layout, str]:
    """Detect the layout of ``src`` and open it with its reader; ``opts`` (``intrinsics``, ``depth_scale``)
    that are None keep the layout's own default."""
    lay, ev = detect(src)
    if lay.name == "capnav-rgbd":
        raise InputError(f"{src} is already a capnav-rgbd dataset ({ev}); map it directly (capnav map {src} ...)")
    if lay.reader is None:
        raise InputError(f"{src} is a ROS bag ({ev}); its topics must be named: capnav import rosbag {src} -o OUT "
                         "--rgb-topic T --depth-topic T --info-topic T --pose-topic T")
    return lay.reader(src, **{k: v for k, v in opts.items() if v is not None}), lay, ev
