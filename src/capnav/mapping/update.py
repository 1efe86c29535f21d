"""Fuse a later recording into an existing map: what moved keeps its id, what is gone retires.

Everything here comes from the new recording's observations (depth, colour, the detector) and
the old map; never from a simulator's list of changes or its instance ids.

1. Every frame (registered into the map frame) is checked against the old map by depth alone
   (``_evidence.classify_points``): each old object's points and each old voxel are SEEN (depth
   agrees), THROUGH (depth reaches past them: that space is free now) or hidden. An object whose
   place was in view, unoccluded and free in enough frames is *observed empty*; one whose points
   were seen again is confirmed present (its last-seen time moves on). A detector's silence
   counts for nothing: detectors miss.
2. Only frames that show surface the old map does not have (something new in view) and their
   neighbours run the detector and the tracker (``Mapper``); the rest of the house costs a depth
   check, not a detection. The objects found there are matched to the old ones: at an old
   object's place they are that object; elsewhere, an object like one observed empty (label,
   colour, size, descriptor) is that object moved (same id, a pose history); the rest are born.
   Old objects observed empty and not found elsewhere are retired (kept, with when they were last
   seen, never returned as present).
3. Voxels seen through are carved, and so is the surface of every object that left its place
   (unless the new recording saw it); the detected frames' voxels are fused in, and the depth of
   frames that saw an old place empty (the floor it stood on); the occupancy grid is derived again.
"""

from __future__ import annotations

import copy
import time
from collections import deque
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from capnav.core.categories import BY_NAME
from capnav.core.errors import FrameError, InputError
from capnav.core.frame import Frame
from capnav.core.lazy import lazy_module
from capnav.core.progress import track
from capnav.io.dataset import DatasetReader
from capnav.mapping.cmap import CameraTrajectory, CapNavMap
from capnav.mapping.label_fit import fitting_label
from capnav.mapping.mapper import Mapper, MapperConfig
from capnav.mapping.memory import labels_compatible, object_box
from capnav.mapping.objects import MapObject
from capnav.mapping.occupancy import occupancy_from_voxels
from capnav.mapping.register import RegisterConfig, Registration, RegistrationError, accept, check_fit, depth_cloud
from capnav.mapping.voxel_map import VoxelMap
from capnav.perception.base import DenseFeatureEncoder, Detector

E_ = lazy_module("capnav.mapping._evidence")


@dataclass(frozen=True)
class UpdateConfig:
    """Evidence: a point is SEEN within ``tol`` of the observed depth, THROUGH when the depth
    reaches ``margin`` past it (points within ``near``..``far`` of the camera). A frame speaks
    about an object when at least ``min_points`` of its points (those ``floor_clearance`` above
    the floor: the floor stays when the object goes) are SEEN or THROUGH; it says *empty* when
    ``empty_share`` of them are THROUGH, *present* when ``present_share`` are SEEN. Retired:
    empty in ``min_empty_frames`` frames and at least twice as often as present. A voxel seen
    through in ``carve_frames`` frames (every ``carve_stride``-th frame is checked), more often
    than seen, is carved.

    Gating: a frame runs the detector when ``new_share`` of its depth (every ``gate_stride``-th
    pixel, at furniture height) lies farther than one ``gate_cell`` from any old surface (0.05
    missed a chair seen from 2 m in 160x120 frames; 0.02 found it), or when an old object seen in
    place looks ``recolour`` away from its mean colour (RGB distance of the averages, the scale of
    the colour cue of ``likeness``); so do ``window`` frames either side (a track needs several
    hits). ``gate=False`` detects in every frame.

    Matching: a new object is an old one when ``same_overlap`` of its points lie within
    ``same_radius`` of that object's points (labels compatible); a moved one when its likeness
    to an object observed empty (descriptor cosine, colour, size) is at least ``min_likeness``;
    one assignment decides all of them, a pair at the same place counting ``place_prior`` more.
    New objects need ``min_hits`` detections to be born.

    Shedding: an object that stays sheds the points whose space was seen empty by the same rule
    (per point), when they are at least ``shed_min`` of its points, ``shed_keep`` remain above the
    floor and a side of its box shrinks by ``shed_side`` (a lamp's pole or a sink's rim seen past
    in a few frames, 10% of their points, changes no box: left as it was); its floor-level points
    stay only within ``shed_floor_radius`` of what remains. A
    neighbour the first map fused into it and that was carried off leaves its box (a 3 m "chair"
    of a sofa and an armchair, Yolo-Fastest, docs/change.md)."""

    tol: float = 0.08
    margin: float = 0.15
    near: float = 0.2
    far: float = 6.0
    min_points: int = 15
    empty_share: float = 0.7
    present_share: float = 0.5
    min_empty_frames: int = 2
    floor_clearance: float = 0.15
    carve_frames: int = 2
    carve_stride: int = 3
    gate: bool = True
    new_share: float = 0.02
    gate_cell: float = 0.1
    gate_stride: int = 4
    gate_top: float = 2.0
    recolour: float = 60.0
    window: int = 2
    same_overlap: float = 0.3
    same_radius: float = 0.1
    min_likeness: float = 0.55
    place_prior: float = 0.3
    min_hits: int = 3
    shed: bool = True
    shed_min: float = 0.25
    shed_keep: float = 0.2
    shed_side: float = 0.15
    shed_floor_radius: float = 0.1
    register: RegisterConfig = field(default_factory=RegisterConfig)


@dataclass
class UpdateReport:
    recording: int
    frames: int = 0
    frames_detected: int = 0
    frames_depth_only: int = 0  # frames that saw an old place empty: depth fused, no detection
    present: list[int] = field(default_factory=list)  # old objects confirmed at their place
    moved: list[int] = field(default_factory=list)
    retired: list[int] = field(default_factory=list)
    born: list[int] = field(default_factory=list)
    unobserved: list[int] = field(default_factory=list)  # old objects the recording did not see
    shrunk: list[int] = field(default_factory=list)  # old objects that shed points seen empty
    voxels_carved: int = 0
    cpu_seconds: float = 0.0
    registration: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in ("recording", "frames", "frames_detected", "frames_depth_only", "present",
                                              "moved", "retired",
                                              "born", "unobserved", "voxels_carved", "registration")} | {
            "cpu_seconds": round(self.cpu_seconds, 3)}

    def summary(self) -> str:
        return (f"recording {self.recording}: {len(self.present)} objects confirmed, {len(self.moved)} moved "
                f"{self.moved}, {len(self.retired)} retired {self.retired}, {len(self.born)} new {self.born}, "
                f"{len(self.unobserved)} not in view, {len(self.shrunk)} shrunk to what was still there; "
                f"detector ran on {self.frames_detected} of {self.frames} "
                f"frames (depth alone fused in {self.frames_depth_only}); {self.voxels_carved} voxels carved free")


# ---- recordings ------------------------------------------------------------------------------
def recordings(cmap: CapNavMap) -> list[dict[str, Any]]:
    """The recordings fused into ``cmap``, oldest first (a map never updated: its one dataset)."""
    recs = cmap.meta.get("recordings")
    if isinstance(recs, list) and recs:
        return [dict(r) for r in recs]
    return [{"index": 1, "dataset": cmap.meta.get("dataset"), "dataset_id": cmap.meta.get("dataset_id"),
             "frames": cmap.meta.get("dataset_frames"), "label": "recording 1"}]


def _label(reader: DatasetReader, index: int) -> str:
    prod = reader.meta.get("meta") or {}
    for key in ("recorded_at", "date"):
        if isinstance(prod.get(key), str):
            return str(prod[key])
    return f"visit {prod['visit']}" if isinstance(prod.get("visit"), int) else f"recording {index}"


def check_same_home(cmap: CapNavMap, reader: DatasetReader, map_name: str) -> None:
    """Refuse another apartment's recording (its producer names another seed) or one already fused."""
    prod = reader.meta.get("meta") or {}
    mine, theirs = cmap.meta.get("scene_seed"), prod.get("seed") if prod.get("source") == "capnav.sim" else None
    if mine is not None and theirs is not None and int(mine) != int(theirs):
        raise InputError(f"{reader.path} is a recording of apartment seed {theirs} but {map_name} maps apartment "
                         f"seed {mine} (made from {cmap.meta.get('dataset', '?')}); an update fuses recordings "
                         "of one home")
    fp = reader.fingerprint()
    for r in recordings(cmap):
        if r.get("dataset_id") == fp:
            raise InputError(f"{reader.path} is recording {r['index']} of {map_name} already (dataset id {fp})")


def register_recording(cmap: CapNavMap, reader: DatasetReader, what: str, init: NDArray[np.float64] | None = None,
                       icp: bool = True, config: RegisterConfig | None = None) -> Registration:
    """The transform from ``reader``'s world frame into ``cmap``'s, checked against the map surface.

    ``icp``: refine ``init`` (default identity) by ICP on the depth (Open3D); without it ``init``
    is only checked. Raises ``RegistrationError`` with the residual when it does not fit."""
    cfg = config or RegisterConfig()
    n = len(reader)
    idx: list[int] = np.unique(np.round(np.linspace(0, n - 1, min(cfg.frames, n))).astype(int)).tolist() if n else []
    frames = []
    for i in idx:
        try:
            frames.append(reader.frame(int(i)))
        except FrameError:
            continue
    src = depth_cloud(frames, cfg)
    vox = cmap.voxels
    tgt = vox.centers()[vox.weights >= 0.02] if len(vox) else np.zeros((0, 3))
    if len(tgt) < 100:
        raise RegistrationError(f"{what}: the map has {len(tgt)} voxels to register against (was it loaded "
                                "without voxels?)")
    T0 = np.eye(4) if init is None else np.asarray(init, dtype=np.float64)
    if icp:
        from capnav.mapping.register import register_icp

        reg = register_icp(src, tgt, T0, cfg)
    else:
        fit, rmse = check_fit(src, tgt, T0, cfg.scales[-1][1])
        reg = Registration(T=T0, fitness=fit, rmse=rmse, method="given transform")
    return accept(reg, cfg, what)


# ---- evidence ------------------------------------------------------------------------------
def _coarse_keys(points: NDArray[np.float64], cell: float) -> NDArray[np.int64]:
    ijk = np.floor(points / cell).astype(np.int64) + (1 << 20)
    return (ijk[:, 0] << 42) | (ijk[:, 1] << 21) | ijk[:, 2]


def _known_surface(vox: VoxelMap, cell: float) -> NDArray[np.int64]:
    """Sorted keys of ``cell`` cubes within one cube of an old voxel (the old map's surface)."""
    base = np.unique(_coarse_keys(vox.centers()[vox.weights >= 0.02], cell))
    offs = np.stack(np.meshgrid(*[np.arange(-1, 2)] * 3, indexing="ij"), axis=-1).reshape(-1, 3).astype(np.int64)
    step = (offs[:, 0] << 42) + (offs[:, 1] << 21) + offs[:, 2]  # neighbours' keys differ by these
    return np.unique((base[:, None] + step[None, :]).ravel())


def _new_share(frame: Frame, T_wc: NDArray[np.float64], known: NDArray[np.int64], cfg: UpdateConfig) -> float:
    s = cfg.gate_stride
    d = np.asarray(frame.depth, dtype=np.float64)[::s, ::s]
    v, u = np.mgrid[0: frame.depth.shape[0]: s, 0: frame.depth.shape[1]: s]
    ok = np.isfinite(d) & (d > cfg.near) & (d <= cfg.far)
    if not ok.any():
        return 0.0
    z = d[ok]
    pc = np.stack([(u[ok] + 0.5 - frame.K.cx) / frame.K.fx * z, (v[ok] + 0.5 - frame.K.cy) / frame.K.fy * z, z,
                   np.ones_like(z)], axis=1)
    pw = (pc @ T_wc.T)[:, :3]
    pw = pw[(pw[:, 2] >= cfg.floor_clearance) & (pw[:, 2] <= cfg.gate_top)]  # furniture height: floor seen
    if len(pw) == 0:  # where a piece stood, or a ceiling, is no new object
        return 0.0
    keys = _coarse_keys(pw, cfg.gate_cell)
    pos = np.searchsorted(known, keys)
    hit = (pos < len(known)) & (known[np.minimum(pos, len(known) - 1)] == keys)
    return float((~hit).sum() / ok.sum())


def _recoloured(frame: Frame, T_cw: NDArray[np.floating], ev: _Evidence, seen: NDArray[np.bool_],
                speaking: NDArray[np.bool_], cfg: UpdateConfig) -> bool:
    """Whether an old object whose place this frame sees filled looks another colour now (its seen
    points' pixels, averaged, ``recolour`` from its mean colour): a white armchair pushed onto the
    place of a pink one leaves the geometry as it was. Averaged per object, so texture and shading
    of single pixels do not count."""
    sel = seen & speaking[ev.owner]
    if not sel.any():
        return False
    p = ev.points[sel]
    pc = p @ T_cw[:3, :3].T + T_cw[:3, 3]
    K = frame.K
    u = np.clip(np.floor(K.fx * pc[:, 0] / pc[:, 2] + K.cx).astype(np.int64), 0, frame.rgb.shape[1] - 1)
    v = np.clip(np.floor(K.fy * pc[:, 1] / pc[:, 2] + K.cy).astype(np.int64), 0, frame.rgb.shape[0] - 1)
    rgb = np.asarray(frame.rgb)[v, u].astype(np.float64)
    own = ev.owner[sel]
    cnt = np.bincount(own, minlength=ev.n).astype(np.float64)
    mean = np.stack([np.bincount(own, rgb[:, c], minlength=ev.n) for c in range(3)], axis=1).astype(np.float64)
    has = cnt > 0
    mean[has] /= cnt[has, None]
    return bool((np.linalg.norm(mean[has] - ev.colour[has], axis=1) > cfg.recolour).any())


@dataclass
class _Evidence:
    points: NDArray[np.float64]  # object points above the floor, all objects concatenated
    owner: NDArray[np.int64]  # index into the old objects of each point
    n: int
    colour: NDArray[np.float64]  # (n, 3) each object's mean colour
    source: NDArray[np.int64]  # index of each point in its object's own points
    present: NDArray[np.int64] = field(init=False)
    empty: NDArray[np.int64] = field(init=False)
    last_present: NDArray[np.int64] = field(init=False)
    point_seen: NDArray[np.int64] = field(init=False)  # per point: frames that saw it
    point_through: NDArray[np.int64] = field(init=False)  # per point: frames that saw past it

    def __post_init__(self) -> None:
        self.present = np.zeros(self.n, np.int64)
        self.empty = np.zeros(self.n, np.int64)
        self.last_present = np.full(self.n, -1, np.int64)
        self.point_seen = np.zeros(len(self.points), np.int64)
        self.point_through = np.zeros(len(self.points), np.int64)

    def vanished(self, q: int, cfg: UpdateConfig) -> NDArray[np.int64]:
        """Indices into object ``q``'s points whose space was seen empty, by the rule that retires
        a whole object (``min_empty_frames``, twice as often as seen)."""
        sel = self.owner == q
        return self.source[sel][_seen_empty(self.point_through[sel], self.point_seen[sel], cfg)]


def _seen_empty(empty: NDArray[np.int64], present: NDArray[np.int64], cfg: UpdateConfig) -> NDArray[np.bool_]:
    """Seen empty in ``min_empty_frames`` frames and at least twice as often as present: the rule
    that retires an object, and sheds a point of one that stays."""
    return (empty >= cfg.min_empty_frames) & (empty >= 2 * present)


def _object_evidence(objects: list[MapObject], cfg: UpdateConfig) -> _Evidence:
    pts, own, src = [], [], []
    for k, o in enumerate(objects):
        p = np.asarray(o.points, dtype=np.float64).reshape(-1, 3)
        idx = np.flatnonzero(p[:, 2] >= cfg.floor_clearance)
        pts.append(p[idx])
        own.append(np.full(len(idx), k, np.int64))
        src.append(idx.astype(np.int64))
    colour = np.array([np.asarray(o.colors, np.float64).mean(axis=0) if len(o.colors) else np.full(3, np.nan)
                       for o in objects]).reshape(-1, 3)
    return _Evidence(np.concatenate(pts) if pts else np.zeros((0, 3)), np.concatenate(own) if own else
                     np.zeros(0, np.int64), len(objects), colour,
                     np.concatenate(src) if src else np.zeros(0, np.int64))


def _shed(o: MapObject, vanished: NDArray[np.int64], cfg: UpdateConfig, percentile: float) -> MapObject | None:
    """``o`` without the points whose space was seen empty, its box and footprint taken again; None
    when it keeps too few (``shed_keep``), or sheds too few (``shed_min``) or too little of its box
    (``shed_side``) to matter. A piece the
    first map fused into it and that left (a sofa beside an armchair, mapped as one "chair") goes
    with its points; the depth evidence is the same that retires whole objects."""
    n = len(o.points)
    if n == 0 or len(vanished) < cfg.shed_min * n:
        return None
    keep = np.ones(n, bool)
    keep[vanished] = False
    p = np.asarray(o.points, np.float64)
    up = keep & (p[:, 2] >= cfg.floor_clearance)
    if up.sum() < cfg.shed_keep * n or up.sum() < cfg.min_points:
        return None
    # its floor-level points go with the space above them: kept only under what stays
    if (~up & keep).any():
        d, _ = cKDTree(p[up, :2]).query(p[~up & keep, :2], distance_upper_bound=cfg.shed_floor_radius)
        keep[np.flatnonzero(~up & keep)[~np.isfinite(d)]] = False
    lo, hi, fp = object_box(o.points[keep], percentile)
    if not ((o.extent_max - o.extent_min)[:2] - (hi - lo)[:2] >= cfg.shed_side).any():
        return None
    c = copy.copy(o)
    c.points, c.colors = o.points[keep].copy(), o.colors[keep].copy()
    c.extent_min, c.extent_max, c.position, c.footprint = lo, hi, (lo + hi) / 2.0, fp
    return c


# ---- matching ------------------------------------------------------------------------------
def _compatible(a: MapObject, b: MapObject) -> bool:
    return labels_compatible(a.label, b.label) or a.label in b.label_votes or b.label in a.label_votes


def _overlap(a: MapObject, b: MapObject, radius: float) -> float:
    if len(a.points) == 0 or len(b.points) == 0:
        return 0.0
    lo, hi = b.extent_min - radius, b.extent_max + radius
    if np.any(a.extent_max < lo) or np.any(a.extent_min > hi):
        return 0.0
    d, _ = cKDTree(b.points).query(a.points, distance_upper_bound=radius)
    return float(np.isfinite(d).mean())


def likeness(a: MapObject, b: MapObject) -> float:
    """How alike two sightings look, in [0, 1]: descriptor cosine, mean colour, size (not place).

    A weighted geometric mean, so that one cue that disagrees outright (a mustard chair and a black
    one of the same make) vetoes however well the others agree; sizes are compared turned (the two
    horizontal sides sorted), since a carried object is rarely set down the same way round."""
    fa, fb = np.asarray(a.feature, np.float64), np.asarray(b.feature, np.float64)
    na, nb = float(np.linalg.norm(fa)), float(np.linalg.norm(fb))
    cos = float(fa @ fb) / (na * nb) if na > 0 and nb > 0 and fa.shape == fb.shape else 0.0
    ca = np.asarray(a.colors, np.float64).mean(axis=0) if len(a.colors) else np.zeros(3)
    cb = np.asarray(b.colors, np.float64).mean(axis=0) if len(b.colors) else np.zeros(3)
    col = float(np.exp(-np.linalg.norm(ca - cb) / 60.0))
    sa, sb = (np.concatenate([np.sort(np.maximum(s[:2], 0.05)), [max(float(s[2]), 0.05)]]) for s in (a.size, b.size))
    size = float(np.exp(-np.abs(np.log(sa / sb)).sum() / 1.5))
    return float(np.exp(0.3 * np.log(max(cos, 1e-3)) + 0.45 * np.log(max(col, 1e-3)) + 0.25 * np.log(size)))


def _assign(new: list[MapObject], old: list[MapObject], gone: NDArray[np.bool_], cfg: UpdateConfig
            ) -> tuple[dict[int, int], dict[int, int], dict[int, int]]:
    """Which old object each new sighting is: (same place: new -> old, moved: old -> new, displaced:
    old -> the new sighting standing at its place).

    One assignment over all pairs (labels compatible), maximising the summed likeness, where a pair
    at the same place (``same_overlap`` of the new points near the old ones) adds ``place_prior``:
    things mostly stay. A pair at different places is allowed only when the old object is free to
    have moved (its place was observed empty, or a new sighting overlaps it: the depth that said
    "present" may be another object standing there) and the two look alike (``min_likeness``).
    So a white armchair pushed onto the pink one's place while the pink one was carried off is the
    white one moved, not the pink one seen again. An old object overlapped by a sighting that the
    assignment gave to another is displaced (gone from its place, unless seen elsewhere)."""
    from scipy.optimize import linear_sum_assignment

    nn, no = len(new), len(old)
    if nn == 0 or no == 0:
        return {}, {}, {}
    score = np.full((nn, no), -np.inf)
    same = np.zeros((nn, no), bool)
    for j, n in enumerate(new):
        for q, o in enumerate(old):
            if _compatible(n, o):
                same[j, q] = _overlap(n, o, cfg.same_radius) >= cfg.same_overlap
    free = gone | same.any(axis=0)
    for j, n in enumerate(new):
        for q, o in enumerate(old):
            if not _compatible(n, o) or not (same[j, q] or free[q]):
                continue
            lk = likeness(n, o)
            if same[j, q]:
                score[j, q] = lk + cfg.place_prior
            elif lk >= cfg.min_likeness:
                score[j, q] = lk
    ok = np.isfinite(score)
    if not ok.any():
        return {}, {}, {}
    rows, cols = linear_sum_assignment(np.where(ok, -score, 1e6))
    claimed: dict[int, int] = {}
    moved: dict[int, int] = {}
    for j, q in zip(rows.tolist(), cols.tolist(), strict=True):
        if not ok[j, q]:
            continue
        if same[j, q]:
            claimed[j] = q
        else:
            moved[q] = j
    taken = set(claimed.values()) | set(moved)
    assigned = sorted({*claimed, *moved.values()})
    displaced = {q: next(j for j in assigned if same[j, q]) for q in range(no)
                 if q not in taken and bool(same[assigned, q].any())}
    return claimed, moved, displaced


# ---- voxels --------------------------------------------------------------------------------
def _merge_voxels(old: VoxelMap, keep: NDArray[np.bool_], new: VoxelMap) -> VoxelMap:
    """``old`` (only ``keep`` voxels) and ``new`` fused: weighted means where both have a voxel."""
    from capnav.mapping._kernels import unpack_keys

    Ko = old.keys[keep]
    W, C, F = old.weights[keep].copy(), old.colors[keep].copy(), old.features[keep].copy()
    if len(new) and len(Ko):
        srt = np.argsort(Ko)
        pos = np.minimum(np.searchsorted(Ko[srt], new.keys), len(Ko) - 1)
        at = srt[pos]
        both = Ko[at] == new.keys
        i, wn = at[both], new.weights[both]
        tot = W[i] + wn
        C[i] = ((C[i] * W[i, None] + new.colors[both] * wn[:, None]) / tot[:, None]).astype(np.float32)
        F[i] = ((F[i] * W[i, None] + new.features[both] * wn[:, None]) / tot[:, None]).astype(np.float32)
        W[i] = tot
        only = ~both
        Ko = np.concatenate([Ko, new.keys[only]])
        W = np.concatenate([W, new.weights[only]])
        C = np.concatenate([C, new.colors[only]])
        F = np.concatenate([F, new.features[only]])
    elif len(new):
        Ko, W, C, F = new.keys, new.weights, new.colors, new.features
    return VoxelMap.from_arrays(old.resolution, old.origin, unpack_keys(Ko), C, W, F, old.projection, old.text_space)


def _fuse_depth(mapper: Mapper, frame: Frame) -> None:
    """Fuse a frame's depth and colour into ``mapper``'s voxels without running the detector."""
    grid, table = mapper.encoder.encode_indexed(frame, [])
    table = np.asarray(table, dtype=np.float32)
    proj = mapper.voxels.project(table) if mapper.voxels.projection is not None else table
    vc = mapper.config.voxel
    mapper.voxels.integrate_frame(frame.depth, frame.rgb, frame.K, frame.T_wc, np.asarray(grid, dtype=np.int64), proj,
                                  vc.sigma, vc.max_depth, vc.pixel_stride)


# ---- the update ----------------------------------------------------------------------------
def update_map(cmap: CapNavMap, reader: DatasetReader, detector: Detector, encoder: DenseFeatureEncoder,
               transform: NDArray[np.float64] | None = None, config: UpdateConfig | None = None,
               mapper_config: MapperConfig | None = None, progress: bool = True,
               registration: Registration | None = None) -> tuple[CapNavMap, UpdateReport]:
    """A new map: ``cmap`` updated with ``reader``'s recording (``transform``: its world frame into
    the map's; identity when None). ``cmap`` itself is not modified."""
    cfg = config or UpdateConfig()
    t_cpu = time.process_time()
    recs = recordings(cmap)
    k = max(int(r.get("index", 0)) for r in recs) + 1
    rep = UpdateReport(recording=k, registration=registration.to_dict() if registration else {})
    T = np.eye(4) if transform is None else np.asarray(transform, dtype=np.float64)
    old = cmap.objects
    ev = _object_evidence(old, cfg)
    vox = cmap.voxels
    vc = vox.centers()
    v_seen = np.zeros(len(vox), np.int64)
    v_through = np.zeros(len(vox), np.int64)
    known = _known_surface(vox, cfg.gate_cell) if len(vox) else np.zeros(0, np.int64)
    mapper = Mapper(mapper_config, detector, encoder)
    if (mapper.voxels.resolution != vox.resolution or mapper.voxels.dim != vox.dim
            or not np.allclose(mapper.voxels.origin, vox.origin)
            or (mapper.voxels.projection is None) != (vox.projection is None)
            or (vox.projection is not None and mapper.voxels.projection is not None
                and not np.array_equal(mapper.voxels.projection, vox.projection))):
        raise InputError(f"the map's voxels (resolution {vox.resolution}, feature dim {vox.dim}, "
                         f"{vox.text_space or '?'}) differ from this mapper's (resolution {mapper.voxels.resolution}, "
                         f"dim {mapper.voxels.dim}, {encoder.text_space}); update with the encoder the map was made "
                         "with")
    poses: list[tuple[int, NDArray[np.float64]]] = []
    pending: deque[Frame] = deque(maxlen=max(cfg.window, 1))
    tail = 0  # frames still to detect after the last changed one
    detected: list[int] = []
    for i in track(range(len(reader)), f"updating with recording {k}", total=len(reader), enabled=progress):
        try:
            f0 = reader.frame(i)
            f0.validate(max_invalid_fraction=mapper.config.max_invalid_depth)
        except FrameError as e:
            mapper.record_skip(i, e.reason)
            continue
        Twc = T @ np.asarray(f0.T_wc, dtype=np.float64)
        f = replace(f0, T_wc=Twc)
        poses.append((i, Twc))
        Tcw = np.linalg.inv(Twc)
        K = f.K
        depth = np.ascontiguousarray(f.depth, dtype=np.float32)
        args = (Tcw, K.fx, K.fy, K.cx, K.cy, depth, cfg.near, cfg.far, cfg.tol, cfg.margin)
        emptied = recoloured = False
        if len(ev.points):
            codes = E_.classify_points(ev.points, *args)
            seen = np.bincount(ev.owner[codes == E_.SEEN], minlength=ev.n)
            thr = np.bincount(ev.owner[codes == E_.THROUGH], minlength=ev.n)
            spoke = seen + thr >= cfg.min_points
            empty = spoke & (thr >= cfg.empty_share * (seen + thr))
            here = spoke & (seen >= cfg.present_share * (seen + thr))
            ev.empty += empty
            ev.point_seen += codes == E_.SEEN
            ev.point_through += codes == E_.THROUGH
            emptied = bool(empty.any())
            recoloured = bool(cfg.recolour > 0) and _recoloured(f, Tcw, ev, codes == E_.SEEN, here, cfg)
            ev.present += here
            ev.last_present[here] = i
        if len(vc) and rep.frames % cfg.carve_stride == 0:
            vcodes = E_.classify_points(vc, *args)
            v_seen += vcodes == E_.SEEN
            v_through += vcodes == E_.THROUGH
        rep.frames += 1
        # A frame shows something new when it holds surface the map lacks: it and its neighbours run
        # the detector. One that sees through an old object's place only has its depth fused (the
        # floor where a chair stood becomes free): what is gone needs no detection.
        changed = not cfg.gate or recoloured or _new_share(f, Twc, known, cfg) >= cfg.new_share
        if changed:
            while pending:
                g = pending.popleft()
                mapper.integrate(g)
                detected.append(g.index)
            tail = cfg.window
        if changed or tail > 0:
            mapper.integrate(f)
            detected.append(f.index)
            if not changed:
                tail -= 1
        elif emptied:
            _fuse_depth(mapper, f)
            rep.frames_depth_only += 1
        else:
            pending.append(f)
    rep.frames_detected = len(detected)
    sub = mapper.finish()
    new_objs = [o for o in sub.objects if o.hits >= cfg.min_hits]

    # -- identity: one assignment of the new sightings to the old objects (``_assign``) --
    gone = _seen_empty(ev.empty, ev.present, cfg)
    seen_again = ev.present > 0
    claimed, moved, displaced = _assign(new_objs, old, gone, cfg)
    for q in set(claimed.values()):
        gone[q] = False
        seen_again[q] = True
    for q in displaced:  # its place holds another object now, and it was not seen elsewhere
        gone[q] = True

    ts = reader.timestamps

    def seen_at(frame: int) -> dict[str, Any]:
        return {"recording": k, "frame": int(frame), "timestamp": float(ts[frame]) if 0 <= frame < len(ts) else None}

    def with_birth(o: MapObject) -> MapObject:
        c = copy.copy(o)
        c.history = list(o.history) or [{"recording": int(recs[0].get("index", 1)), "event": "born",
                                         "position": np.round(o.position, 3).tolist(), "frame": int(o.first_frame)}]
        if c.last_seen is None:
            c.last_seen = {"recording": int(recs[-1].get("index", 1)), "frame": int(o.last_frame), "timestamp": None}
        return c

    next_id = max([int(cmap.meta.get("next_object_id", 1)) - 1, *(o.id for o in old),
                   *(o.id for o in cmap.retired)], default=0) + 1
    present: list[MapObject] = []
    retired: list[MapObject] = list(cmap.retired)
    for q, o in enumerate(old):
        c = with_birth(o)
        if q in moved:
            n = new_objs[moved[q]]
            m = copy.copy(n)
            m.id, m.caption, m.caption_source = o.id, o.caption, o.caption_source
            m.embedding, m.embedding_model = o.embedding, o.embedding_model
            m.views = []  # seen elsewhere now: views from this recording are chosen by `capnav caption`
            m.label_votes = {lb: o.label_votes.get(lb, 0.0) + n.label_votes.get(lb, 0.0)
                             for lb in sorted(set(o.label_votes) | set(n.label_votes))}
            m.label = max(m.label_votes, key=lambda lb: (m.label_votes[lb], lb)) if m.label_votes else o.label
            m.label = fitting_label(m.label_votes, m.points, mapper.config.memory.label_fit)[0] or m.label  # label_fit
            m.category_id = o.category_id if m.label == o.label else n.category_id if m.label == n.label \
                else getattr(BY_NAME.get(m.label), "id", 0)
            m.history = [*c.history, {"recording": k, "event": "moved", "position": np.round(n.position, 3).tolist(),
                                      "from": np.round(o.position, 3).tolist(), "frame": int(n.last_frame),
                                      "frames_empty": int(ev.empty[q])}]
            m.last_seen = seen_at(n.last_frame)
            present.append(m)
            rep.moved.append(o.id)
        elif gone[q]:
            c.history = [*c.history, {"recording": k, "event": "retired", "position": np.round(o.position, 3).tolist(),
                                      "frames_empty": int(ev.empty[q]), "frames_present": int(ev.present[q])}]
            if q in displaced:  # not seen empty: another object stands where it stood
                n = new_objs[displaced[q]]
                c.history[-1]["replaced_by"] = {"label": n.label, "position": np.round(n.position, 3).tolist()}
            retired.append(c)
            rep.retired.append(o.id)
        else:
            shed = _shed(c, ev.vanished(q, cfg), cfg, mapper.config.memory.extent_percentile) if cfg.shed else None
            if shed is not None:
                c = shed
                c.history = [*c.history, {"recording": k, "event": "shrunk",
                                          "position": np.round(c.position, 3).tolist(),
                                          "points_seen_empty": int(len(o.points) - len(c.points))}]
                rep.shrunk.append(o.id)
            if seen_again[q]:
                last = int(ev.last_present[q])
                claimed_by = [new_objs[j] for j, qq in claimed.items() if qq == q]
                last = max([last, *(int(n.last_frame) for n in claimed_by)])
                c.last_seen = seen_at(last)
                rep.present.append(o.id)
            else:
                rep.unobserved.append(o.id)
            present.append(c)
    taken = set(claimed) | set(moved.values())
    for j, n in enumerate(new_objs):
        if j in taken:
            continue
        b = copy.copy(n)
        b.id = next_id
        next_id += 1
        b.history = [{"recording": k, "event": "born", "position": np.round(n.position, 3).tolist(),
                      "frame": int(n.first_frame)}]
        b.last_seen = seen_at(n.last_frame)
        present.append(b)
        rep.born.append(b.id)
    present.sort(key=lambda o: o.id)

    # -- geometry: carve what was seen through, fuse what was detected, derive occupancy again --
    carve = (v_through >= cfg.carve_frames) & (v_through > v_seen)
    # An object that left its place takes its surface with it: the voxels of its points go, unless
    # the new recording saw them (something else stands there now). The object's evidence came
    # from every frame; the voxels' own count only from every ``carve_stride``-th one.
    left = [q for q, o in enumerate(old) if q in moved or gone[q]]
    if left and len(vox):
        own = np.concatenate([np.asarray(old[q].points, np.float64).reshape(-1, 3) for q in left])
        own = own[own[:, 2] >= mapper.config.occupancy.floor_max]  # the floor under it stays
        slots = vox.slots(vox.index_of(own))
        slots = np.unique(slots[slots >= 0])
        carve[slots[v_seen[slots] == 0]] = True
        # Its masks may have missed part of its surface (a strip no mask held is voxels no object
        # owns): inside its box, above the floor, what no object that stays owns and the new
        # recording did not see goes too, else specks of it stay obstacles where it stood.
        stay = [np.asarray(o.points, np.float64).reshape(-1, 3) for q, o in enumerate(old) if q not in left]
        owned = np.zeros(len(vox), bool)
        if stay:
            s_slots = vox.slots(vox.index_of(np.concatenate(stay)))
            owned[s_slots[s_slots >= 0]] = True
        floor = mapper.config.occupancy.floor_max
        for q in left:
            lo, hi = np.asarray(old[q].extent_min, np.float64), np.asarray(old[q].extent_max, np.float64)
            inside = np.all((vc >= lo) & (vc <= hi), axis=1) & (vc[:, 2] >= floor)
            carve[inside & ~owned & (v_seen == 0)] = True
    rep.voxels_carved = int(carve.sum())
    voxels = _merge_voxels(vox, ~carve, sub.voxels)
    occ = occupancy_from_voxels(voxels, mapper.config.occupancy)
    traj = cmap.trajectory
    if poses:
        fr = np.array([i for i, _ in poses], dtype=np.int64)
        ps = np.stack([p for _, p in poses])
        traj = CameraTrajectory(np.concatenate([traj.frames, fr]), np.concatenate([traj.poses, ps])) \
            if traj is not None else CameraTrajectory(fr, ps)
    rep.cpu_seconds = time.process_time() - t_cpu
    meta = dict(cmap.meta)
    rec = {"index": k, "dataset": str(reader.path.resolve()), "dataset_id": reader.fingerprint(), "frames": len(reader),
           "label": _label(reader, k), "transform": np.round(T, 9).tolist()}
    meta["recordings"] = [*recs, rec]
    meta.update({"dataset": rec["dataset"], "dataset_id": rec["dataset_id"], "dataset_frames": len(reader),
                 "next_object_id": next_id})
    meta["updates"] = [*meta.get("updates", []), rep.to_dict() | {"frames_skipped": list(mapper.skipped)}]
    out = CapNavMap(objects=present, voxels=voxels, occupancy=occ, meta=meta, caches=copy.deepcopy(cmap.caches),
                    trajectory=traj, retired=retired)
    return out, rep


__all__ = ["RegistrationError", "UpdateConfig", "UpdateReport", "check_same_home", "likeness", "recordings",
           "register_recording", "update_map"]
