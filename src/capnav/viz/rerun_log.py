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

from capnav.core.errors import InputError, pip_hint
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
        raise InputError(f"3D views need the viz extra: {pip_hint('capnav[viz]')} ({e})") from None
    have = tuple(int(v) for v in rr.__version__.split(".")[:2])
    if have != RERUN_MINOR:
        raise InputError(f"capnav's 3D views are written for rerun-sdk {RERUN_MINOR[0]}.{RERUN_MINOR[1]}.x, found "
                         f"{rr.__version__}: {pip_hint('capnav[viz]')}")
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


def log_map(rec: Any, cmap: CapNavMap, max_voxels: int = 300_000, seed: int = 0, max_z: float | None = None) -> None:
    """Log the map itself (static entities and the camera's timeline) to ``rec``. ``max_z`` leaves
    out the voxels whose centre is above it (the ceiling hides the rooms from above)."""
    rr = _rerun()
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    vox = cmap.voxels
    if len(vox):
        centres = vox.centers()
        colours = np.clip(np.asarray(vox.colors), 0, 255).astype(np.uint8)
        if max_z is not None:
            below = centres[:, 2] <= max_z
            centres, colours = centres[below], colours[below]
        if len(centres) > max_voxels:  # a seeded subsample keeps huge maps viewable
            keep = np.sort(np.random.default_rng(seed).choice(len(centres), max_voxels, replace=False))
            centres, colours = centres[keep], colours[keep]
        if len(centres):
            rec.log("world/map/voxels", rr.Points3D(centres, colors=colours, radii=0.5 * vox.resolution),
                    static=True)
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
                                                 colors=[RUNNER_RGB] * len(ro), radii=0.01, show_labels=False),
                static=True)  # their own "id CATEGORY" labels are already on screen; scores show on hover
    if plan is not None and len(plan.poses) > 1:
        pts = np.column_stack([plan.poses[:, :2], np.full(len(plan.poses), 0.05)])
        rec.log("world/path", rr.LineStrips3D([pts], colors=PATH_RGB, radii=0.05,
                                              labels=[f"{plan.length_m:.2f} m"]), static=True)


def eye_pose(cmap: CapNavMap) -> tuple[list[float], list[float]]:
    """Where the 3D view starts: looking down at about 50 degrees from south of the map (-y) onto
    its centre on the floor, far enough back to see the whole floor plan."""
    spec = cmap.occupancy.spec
    lo = np.array([spec.x0, spec.y0], dtype=np.float64)
    size = np.array([spec.cols, spec.rows], dtype=np.float64) * spec.resolution
    if len(cmap.voxels):
        c = cmap.voxels.centers()[:, :2]
        lo, size = c.min(axis=0), np.ptp(c, axis=0)
    centre = lo + size / 2
    span = float(max(size.max(), 1.0))
    eye = [float(centre[0]), float(lo[1] - 0.45 * size[1]), span]
    return eye, [float(centre[0]), float(centre[1] + 0.05 * size[1]), 0.0]


def map_blueprint(cmap: CapNavMap, answers: Sequence[tuple[Answer, Plan | None]] = ()) -> Any:
    """The layout the recording opens with: the 3D map from above and, per answer, its reason
    and the chosen object's captioning view beside it (rerun's own guess puts every caption in a
    view of its own)."""
    rr = _rerun()
    rrb = rr.blueprint
    eye, target = eye_pose(cmap)
    space = rrb.Spatial3DView(origin="world", name="map", eye_controls=rrb.EyeControls3D(position=eye,
                                                                                        look_target=target))
    side: list[Any] = []
    for n, (ans, _) in enumerate(answers):
        side.append(rrb.TextDocumentView(origin=f"world/query/{n}/reason", name=f"answer {n}"))
        if ans.object is not None and any(v.frame_png for v in cmap.object(ans.object.id).views):
            side.append(rrb.Spatial2DView(origin=f"views/{ans.object.id}", name=f"view of {ans.object.id}"))
    root = rrb.Horizontal(space, rrb.Vertical(*side), column_shares=[3, 1]) if side else space
    return rrb.Blueprint(root, rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                         rrb.TimePanel(state="collapsed"))


def write_rrd(cmap: CapNavMap, out: str | Path, answers: Sequence[tuple[Answer, Plan | None]] = (),
              connect: str | None = None, max_voxels: int = 300_000, max_z: float | None = None) -> Path | None:
    """Log the map and the answers to ``out`` (an ``.rrd`` file), or to the viewer at ``connect``
    (a rerun gRPC URL) when given; ``max_z`` as in ``log_map``. Returns the file written."""
    rr = _rerun()
    rec = rr.RecordingStream("capnav", recording_id=str(cmap.meta.get("eval_key") or "capnav-map"))
    path = None
    layout = map_blueprint(cmap, answers)
    if connect:
        rec.connect_grpc(connect, default_blueprint=layout)
    else:
        path = Path(out)
        if path.suffix != ".rrd":
            raise InputError(f"the output must be an .rrd file, got {path}")
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".part")
        rec.save(tmp, default_blueprint=layout)
    log_map(rec, cmap, max_voxels=max_voxels, max_z=max_z)
    for n, (ans, plan) in enumerate(answers):
        log_answer(rec, cmap, ans, n, plan)
    rec.flush()
    rec.disconnect()
    if path is not None:
        tmp.replace(path)  # atomic: a reader never sees a half-written recording
    return path
