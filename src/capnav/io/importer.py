"""Turn an associated recording (TUM folder, ROS bag) into a ``capnav-rgbd`` dataset folder.

Shared by every importer: frame selection (stride, max frames), floor alignment, per-frame checks
with counted skip reasons, and an all-or-nothing write (the dataset is built in a hidden sibling
folder and renamed into place only once complete, so an interrupted import leaves nothing behind).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from capnav.core.atomic import atomic_dir
from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics
from capnav.core.progress import track
from capnav.io.align import Alignment, floor_alignment
from capnav.io.assoc import SkipLog
from capnav.io.consistency import READINGS, Consistency, check, pair_up
from capnav.io.up_axis import CUES, UpConfig


@dataclass(frozen=True)
class PlannedFrame:
    """An associated (colour, depth, pose) triple of a recording, before its images are read."""

    name: str  # how the user finds it in the recording (colour file, or topic and stamp)
    timestamp: float
    T_wc: NDArray[np.float64]  # in the recording's world
    rgb: Any  # the reader's handle for the colour image
    depth: Any  # ... and for the depth image
    source_index: int = -1  # the frame's number in the recording (its order in the source)


class Recording(Protocol):
    """What an importer reader provides: associated frames, skips so far, intrinsics, image loading."""

    path: Path
    kind: str
    K: Intrinsics
    frames: list[PlannedFrame]
    skipped: SkipLog
    meta: dict[str, Any]

    def load_depths(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.float32]]]: ...

    def load(self, frames: list[PlannedFrame]) -> Iterator[
        tuple[PlannedFrame, NDArray[np.uint8], NDArray[np.float32]]]: ...


@dataclass
class ImportReport:
    out: Path
    kind: str
    associated: int  # colour frames with depth and pose
    selected: int  # after --stride / --max-frames
    written: int
    skipped: SkipLog
    alignment: Alignment
    seconds: float
    meta: dict[str, Any] = field(default_factory=dict)

    def lines(self) -> list[str]:
        """Human summary: what was written, how the world was aligned, and every skip reason with examples."""
        a = self.alignment.info
        out = [f"{self.out}: {self.written} frames written from the {self.kind} recording "
               f"({self.associated} associated, {self.selected} selected) in {self.seconds:.1f} s"]
        if a.get("method") in ("floor-auto", "floor-named"):
            how = ("up found" if a["method"] == "floor-auto" else
                   f"floor aligned (--up {self.alignment.up}, {a['tilt_from_up_deg']:.1f} deg from it)")
            up = ", ".join(f"{v:+.3f}" for v in a["up_in_recording"])
            f = a["facts"]
            out.append(f"{how}: the recording's ({up}), {a['axis_angle_deg']:.1f} deg from {a['nearest_axis']}; "
                       f"confidence {a['confidence']:.2f} (" + ", ".join(f"{c} {a['cues'][c]:.2f}" for c in CUES)
                       + f"); floor {a['floor_points']} points ({100 * f['floor_share']:.0f}%), rms "
                       f"{100 * a['floor_rms_m']:.1f} cm, cameras {f['camera_height_median_m']:.2f} m above it, "
                       f"image-down {f['upright_deg']:.0f} deg from gravity")
            r = a.get("floor_runner_up")
            out.append(f"floor confidence {a['floor_confidence']:.2f} ({f['floor_area_m2']:.1f} m2 seen); "
                       + ("no other plane faces up" if r is None else
                          f"runner-up plane {r['height_m']:+.2f} m above the floor: {int(r['points'])} points "
                          f"({r['points'] / max(a['floor_points'], 1):.1f}x the floor's), {r['area_m2']:.1f} m2"))
            h, (lo, hi) = f["camera_height_median_m"], UpConfig().usual_height
            if not lo <= h <= hi:
                out.append(f"warning: the cameras are {h:.2f} m above the floor found, an implausible height for a "
                           "hand-held or robot camera: is the depth scale right (--depth-scale: units per metre)?")
        else:
            out.append("world frame kept as recorded (--up none)")
        c = self.meta.get("consistency") or {}
        if c.get("verdict") == "weak":
            out.append(f"warning: poses against depth: {c['reason']}")
        elif c.get("verdict") == "consistent":
            out.append(f"poses checked against depth: {c['reason']}")
        for reason, n in self.skipped.counts().items():
            ex = "; ".join(f"{s.name}" + (f" ({s.detail})" if s.detail else "") for s in self.skipped.examples(reason))
            out.append(f"skipped {n}: {reason} (e.g. {ex})")
        return out


def select(frames: list[PlannedFrame], stride: int = 1, max_frames: int | None = None) -> list[PlannedFrame]:
    """Every ``stride``-th associated frame, then the first ``max_frames`` (as ``capnav map --max-frames``)."""
    if stride < 1:
        raise InputError(f"--stride must be >= 1, got {stride}")
    if max_frames is not None and max_frames < 1:
        raise InputError(f"--max-frames must be >= 1, got {max_frames}")
    return frames[::stride][:max_frames]


def other_reading(views: list[tuple[NDArray[np.float32], NDArray[np.float64]]], poses: NDArray[np.float64],
                  K: Intrinsics, floor: UpConfig | None) -> str:
    """When up cannot be found as the poses are read: the other pose reading (``capnav.io.consistency``)
    under which it is found with confidence, as words for the error, or ''."""
    for rd in READINGS[1:]:
        if rd.depth_factor != 1.0:
            continue
        try:
            a = floor_alignment([(d, rd.pose(T)) for d, T in views], K, "auto", floor,
                                poses=np.stack([rd.pose(T) for T in poses]))
        except InputError:
            continue
        return (f"{rd.meaning}: read that way, up is found (confidence {a.info['confidence']:.2f}, cameras "
                f"{a.info['facts']['camera_height_median_m']:.2f} m above the floor), as read it is not"
                + (f"; {rd.remedy}" if rd.remedy else ""))
    return ""


def check_poses(rec: Recording, frames: list[PlannedFrame], shape: tuple[int, int]) -> Consistency:
    """The reprojection check of ``capnav.io.consistency`` on neighbouring selected frames."""
    pairs = pair_up([f.T_wc for f in frames])
    wanted = [frames[k] for ij in pairs for k in ij]
    got = {id(f): d for f, d in rec.load_depths(wanted) if d.shape == shape}
    both = [(i, j) for i, j in pairs if id(frames[i]) in got and id(frames[j]) in got]
    return check([got[id(frames[k])] for ij in both for k in ij], [frames[k].T_wc for ij in both for k in ij],
                 rec.K)


def import_recording(rec: Recording, out: str | Path, up: str = "auto", stride: int = 1,
                     max_frames: int | None = None, overwrite: bool = False, progress: bool = True,
                     align_frames: int = 30, floor: UpConfig | None = None) -> ImportReport:
    """Write ``rec`` as a ``capnav-rgbd`` folder at ``out`` with every pose aligned (``T_wc' = A @ T_wc``)."""
    from capnav.io.dataset import DatasetWriter, check_dataset_target

    t0 = time.monotonic()
    out = Path(out)
    check_dataset_target(out, overwrite)
    frames = select(rec.frames, stride, max_frames)
    if not frames:
        counts = ", ".join(f"{n} {r}" for r, n in rec.skipped.counts().items()) or "none in the recording"
        raise InputError(f"{rec.path}: no frame to import (skipped: {counts})")
    shape = (rec.K.height, rec.K.width)
    consistency = check_poses(rec, frames, shape)
    if consistency.verdict == "refused":
        raise InputError(f"{rec.path}: the poses and the depth do not fit together as read; {consistency.reason}")
    pick = np.unique(np.round(np.linspace(0, len(frames) - 1, min(align_frames, len(frames)))).astype(int))
    views = [(d, f.T_wc) for f, d in rec.load_depths([frames[i] for i in pick]) if d.shape == shape]
    poses = np.stack([f.T_wc for f in frames])
    try:
        align = floor_alignment(views, rec.K, up, floor, poses=poses)
    except InputError as e:
        hint = other_reading(views, poses, rec.K, floor)
        if not hint:
            raise
        raise InputError(f"{rec.path}: {hint} (as the poses are read: {e})") from None

    skipped = SkipLog(list(rec.skipped.skips))
    n_before = len(rec.skipped.skips)  # the reader counts frames it cannot load while they are written
    meta: dict[str, Any] = {"source": rec.kind, "recording": str(rec.path), **rec.meta,
                            "alignment": align.to_meta(), "consistency": consistency.to_meta()}
    sources: list[list[Any]] = []  # per written frame: where it came from
    with atomic_dir(out, overwrite=True) as tmp:  # the target was checked above
        w = DatasetWriter(tmp, rec.K, meta, write_gt=False)
        for f, rgb, depth in track(rec.load(frames), f"importing {rec.path.name}", total=len(frames),
                                   enabled=progress):
            if rgb.shape[:2] != shape or depth.shape != shape:
                skipped.add(f.name, f.timestamp, "bad size",
                            f"rgb {rgb.shape[1]}x{rgb.shape[0]}, depth {depth.shape[-1]}x{depth.shape[0]}, "
                            f"intrinsics {shape[1]}x{shape[0]}")
                continue
            valid = np.isfinite(depth) & (depth > 0)
            if not valid.any():
                skipped.add(f.name, f.timestamp, "no valid depth", "every depth pixel is 0 or non-finite")
                continue
            depth = np.where(valid, depth, 0.0).astype(np.float32)
            sources.append([len(w), f.source_index, f.timestamp, f.name])
            w.write(Frame(index=len(w), rgb=rgb, depth=depth, K=rec.K, T_wc=align.A @ f.T_wc, timestamp=f.timestamp))
        skipped.skips.extend(rec.skipped.skips[n_before:])
        if len(w) == 0:
            raise InputError(f"{rec.path}: every selected frame was skipped ({skipped.counts()})")
        w.meta["import"] = {"associated": len(rec.frames), "selected": len(frames), "written": len(w),
                            "skipped": skipped.counts(),
                            "skipped_examples": {r: [s.name for s in skipped.examples(r)] for r in skipped.counts()},
                            "frames_columns": ["index", "source_index", "timestamp", "name"], "frames": sources}
        w.close()
    return ImportReport(out, rec.kind, len(rec.frames), len(frames), w.meta["import"]["written"], skipped, align,
                        time.monotonic() - t0, meta)


