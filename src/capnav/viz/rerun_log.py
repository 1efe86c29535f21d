"""3D views of a map with rerun (the ``viz`` extra, pinned to rerun-sdk 0.41): the voxel map with
its colours, the occupancy, every object's box (labelled "id CATEGORY") with its points, caption
and captioning view, the camera's path, and a query's answer with its planned path.

Everything goes to an explicit ``RecordingStream`` (never rerun's global one), saved to ``.rrd``
or sent to a running viewer. Entity paths (world frame right-handed, z up, metres):

    world                          ViewCoordinates RIGHT_HAND_Z_UP
    world/map/voxels               Points3D, voxel colours, radius half a voxel
    world/map/occupancy            Points3D at z = 0, one per occupied cell
    world/objects                  Boxes3D, labels "id CATEGORY", a colour per category
    world/objects/<id>/points      Points3D of the object's fused surface sample
    world/objects/<id>/caption     TextDocument
    views/<id>                     EncodedImage: the view chosen for captioning (2D)
    world/camera                   Transform3D = T_wc on the ``frame`` sequence (child camera -> world)
    world/camera_path              LineStrips3D of the camera centres
    world/query/<n>                Boxes3D of the chosen object (+ runners_up), TextDocument reason
    world/path                     LineStrips3D of the planned path, 5 cm above the floor
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.grid import OCCUPIED
from capnav.mapping.cmap import CapNavMap

if TYPE_CHECKING:
    from capnav.api import Answer, Plan

RERUN_MINOR = (0, 41)
CHOSEN_RGB = (255, 190, 0)
RUNNER_RGB = (40, 120, 255)
PATH_RGB = (0, 170, 80)


def _rerun() -> Any:
    try:
        import rerun as rr
    except ImportError as e:
        raise InputError(f"3D views need the viz extra: pip install 'capnav[viz]' ({e})") from None
    have = tuple(int(v) for v in rr.__version__.split(".")[:2])
    if have != RERUN_MINOR:
        raise InputError(f"capnav's 3D views are written for rerun-sdk {RERUN_MINOR[0]}.{RERUN_MINOR[1]}.x, found "
                         f"{rr.__version__}: pip install 'capnav[viz]'")
    return rr


def category_rgb(name: str) -> tuple[int, int, int]:
    """A stable, saturated colour per category name (the same in every run and every map)."""
    h = int(hashlib.sha256(name.encode()).hexdigest()[:4], 16) / 0xFFFF
    import colorsys

    r, g, b = colorsys.hsv_to_rgb(h, 0.65, 0.95)
    return (int(r * 255), int(g * 255), int(b * 255))


def camera_path(cmap: CapNavMap) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Frame indices and (N, 4, 4) ``T_wc`` of the frames the map was built from ((0,) / (0, 4, 4)
    for maps written before maps stored the camera trajectory)."""
    traj = cmap.trajectory
    if traj is None:
        return np.zeros(0, np.int64), np.zeros((0, 4, 4))
    return np.asarray(traj.frames, dtype=np.int64), np.asarray(traj.poses, dtype=np.float64)


def log_map(rec: Any, cmap: CapNavMap, max_voxels: int = 300_000, seed: int = 0) -> None:
    """Log the map itself (static entities and the camera's timeline) to ``rec``."""
    rr = _rerun()
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    vox = cmap.voxels
    if len(vox):
        centres = vox.centers()
        colours = np.clip(np.asarray(vox.colors), 0, 255).astype(np.uint8)
        if len(centres) > max_voxels:  # a seeded subsample keeps huge maps viewable
            keep = np.sort(np.random.default_rng(seed).choice(len(centres), max_voxels, replace=False))
            centres, colours = centres[keep], colours[keep]
        rec.log("world/map/voxels", rr.Points3D(centres, colors=colours, radii=0.5 * vox.resolution), static=True)
    occ = cmap.occupancy
    rc = np.argwhere(occ.cells == OCCUPIED)
    if len(rc):
        xy = occ.spec.to_world(rc)
        rec.log("world/map/occupancy", rr.Points3D(np.column_stack([xy, np.zeros(len(xy))]), colors=(60, 60, 70),
                                                   radii=0.5 * occ.spec.resolution), static=True)
    objs = cmap.objects
    if objs:
        mins = np.array([o.extent_min for o in objs], dtype=np.float64)
        sizes = np.array([o.extent_max - o.extent_min for o in objs], dtype=np.float64)
        rec.log("world/objects", rr.Boxes3D(mins=mins, sizes=sizes, labels=[f"{o.id} {o.label.upper()}" for o in objs],
                                            colors=[category_rgb(o.label) for o in objs], show_labels=True),
                static=True)
    for o in objs:
        if len(o.points):
            rec.log(f"world/objects/{o.id}/points", rr.Points3D(o.points, colors=o.colors, radii=0.01), static=True)
        rec.log(f"world/objects/{o.id}/caption", rr.TextDocument(o.caption or f"{o.label} (not captioned)"),
                static=True)
        png = next((v.frame_png for v in o.views if v.frame_png), b"")
        if png:
            rec.log(f"views/{o.id}", rr.EncodedImage(contents=png, media_type="image/png"), static=True)
    frames, T = camera_path(cmap)
    if len(frames):
        for i, Twc in zip(frames, T, strict=True):
            rec.set_time("frame", sequence=int(i))
            rec.log("world/camera", rr.Transform3D(translation=Twc[:3, 3], mat3x3=Twc[:3, :3]))
        rec.reset_time()
        rec.log("world/camera_path", rr.LineStrips3D([T[:, :3, 3]], colors=(120, 120, 255), radii=0.01),
                static=True)


def log_answer(rec: Any, cmap: CapNavMap, answer: Answer, n: int = 0, plan: Plan | None = None) -> None:
    """Log one query's answer as ``world/query/<n>`` and, when given, its path as ``world/path``."""
    rr = _rerun()
    base = f"world/query/{n}"
    rec.log(base, rr.Clear(recursive=True), static=True)  # a re-logged query replaces the old one whole
    rec.log(f"{base}/reason", rr.TextDocument(f"{answer.instruction}\n\n{answer.reason}"), static=True)
    if answer.object is not None:
        o = cmap.object(answer.object.id)
        rec.log(f"{base}/chosen", rr.Boxes3D(mins=[o.extent_min], sizes=[o.extent_max - o.extent_min],
                                             labels=[f"{o.id} {o.label.upper()}: {answer.instruction}"],
                                             colors=[CHOSEN_RGB], radii=0.02, show_labels=True), static=True)
    if answer.runners_up:
        ro = [cmap.object(r.id) for r, _ in answer.runners_up]
        rec.log(f"{base}/runners_up", rr.Boxes3D(mins=[o.extent_min for o in ro],
                                                 sizes=[o.extent_max - o.extent_min for o in ro],
                                                 labels=[f"{r.id} ({s:.2f})" for r, s in answer.runners_up],
                                                 colors=[RUNNER_RGB] * len(ro), radii=0.01), static=True)
    if plan is not None and len(plan.poses) > 1:
        pts = np.column_stack([plan.poses[:, :2], np.full(len(plan.poses), 0.05)])
        rec.log("world/path", rr.LineStrips3D([pts], colors=PATH_RGB, radii=0.03,
                                              labels=[f"{plan.length_m:.2f} m"]), static=True)


def write_rrd(cmap: CapNavMap, out: str | Path, answers: Sequence[tuple[Answer, Plan | None]] = (),
              connect: str | None = None, max_voxels: int = 300_000) -> Path | None:
    """Log the map and the answers to ``out`` (an ``.rrd`` file), or to the viewer at ``connect``
    (a rerun gRPC URL) when given. Returns the file written."""
    rr = _rerun()
    rec = rr.RecordingStream("capnav", recording_id=str(cmap.meta.get("eval_key") or "capnav-map"))
    path = None
    if connect:
        rec.connect_grpc(connect)
    else:
        path = Path(out)
        if path.suffix != ".rrd":
            raise InputError(f"the output must be an .rrd file, got {path}")
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".part")
        rec.save(tmp)
    log_map(rec, cmap, max_voxels=max_voxels)
    for n, (ans, plan) in enumerate(answers):
        log_answer(rec, cmap, ans, n, plan)
    rec.flush()
    rec.disconnect()
    if path is not None:
        tmp.replace(path)  # atomic: a reader never sees a half-written recording
    return path
