"""Persistent object memory: what survives the tracker (the paper's tracks die; a map must not).

A track feeds nothing until it is confirmed (``h_min`` hits); its first detections are buffered.
A track that dies unconfirmed leaves its buffer behind (``pool_unconfirmed``): a later track whose
detection overlaps it in 3D with a compatible label takes it over, and its hits count towards that
track's ``h_min``. Confirmation counts the detections of one 3D thing, not of one track: a small
object seen in a few frames scattered more than ``m_max`` apart (a plant glimpsed on passing)
would otherwise be split over short tracks that each die below ``h_min``.
Weak candidates (``Detection.weak``) count towards confirmation only under the stricter rule of
``TrackerConfig.weak_h_min`` (``_confirms``): several sightings in 3D agreement whose leading
label is both strong enough in sum and the clear majority of their label scores (a place the
detector calls a table, a chair, a couch and a bed in turn is not confirmed as any of them). A
place confirmed that way which lies on an object's points is that object (whatever the labels),
and weak votes name an object only while it has no confident vote.
On confirmation it is linked either to an existing object (a revisit: the buffered points overlap
the object's points in 3D and the labels agree) or to a new object. Linked tracks add every later
detection to their object. When the track dies the object stays. ``finish`` merges duplicates
(objects whose points overlap, with compatible labels, never seen together in a frame) and builds
``MapObject``s with a bounded point sample, extent, footprint and bounded observations.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError, cKDTree

from capnav.core.categories import BY_NAME, confusable
from capnav.core.errors import InputError
from capnav.mapping.box_carving import DepthViews, carve
from capnav.mapping.corroborate import corroborated
from capnav.mapping.label_fit import LabelFitConfig, fitting_label
from capnav.mapping.lifting import LiftedDetection
from capnav.mapping.objects import MapObject, Observation
from capnav.mapping.support import stands_on
from capnav.mapping.tracker import Track, TrackerConfig, vote_weight


@dataclass(frozen=True)
class MemoryConfig:
    """``point_voxel`` dedupes an object's points (3 cm), ``max_points`` caps them (seeded sample);
    ``max_observations`` keeps the most useful sightings (score x visibility x sqrt(area), halved
    when truncated). A track re-associates with / an object merges into another when at least
    ``min_overlap`` of its points lie within ``overlap_radius`` of the other's points, or
    ``min_inside`` of them inside the other's box grown by ``overlap_radius``, and labels are
    compatible (equal, in one confusion group, or descriptor cosine >= ``min_cos``). Objects seen
    together in more than ``max_covisible`` frames are distinct and never merged, unless they are
    one thing: at least ``same_overlap`` of the smaller one's points lie within ``overlap_radius``
    of the other's (a part inside its whole, or one object mapped twice under two labels by a
    real detector); those merge at export whatever their labels, the label votes summed (> 1
    turns this off), unless the smaller stands on the other (``support.stands_on``: a bowl on a
    desk). 0.6 and 0.8 merged two distinct objects of generated apartment 2
    (``benchmarks/bench_mapping.py --seeds 2 --quality-only``: recall 96%); 0.95 keeps them apart.

    ``recheck``: eq. 12 can hand a track the detection of a same-class neighbour when the right
    object is missed in that frame (0.8 m apart costs 0.68 < tau). A detection of a linked track
    whose points lie outside the object's box grown by ``recheck_margin`` (fraction inside below
    ``recheck_inside``) and almost nowhere near its points is re-linked by overlap, as on
    confirmation, instead of corrupting the object.

    ``pool_unconfirmed``: the buffered detections of a track that died before ``h_min`` hits are
    kept and count for a later track of the same thing (3D overlap as above, compatible label or
    descriptor), so ``h_min`` detections of one place make an object however far apart in time;
    random false positives (random place and label) still never add up. On by default: it finds
    the small and glimpsed things (seed 100's cactus, the demo apartment's fifth armchair,
    Yolo-Fastest recall 33 -> 40% on Sweet Home 3D seed 0 at 100% precision). It was off while
    the room regions hung on one row of cells: on the demo apartment a plant stands in a pocket of
    free space between a wall, a bookshelf and a sofa whose way out, in the pooled map, is a
    strip no frame saw, so the pocket was reached from no room and only the office's cells across
    the wall voted in ``object_region``. Pockets now take the room they open into through unseen
    cells (``language.rooms.room_regions``) and only cells joined to an object's own vote.
    Pooled detections help confirm a thing, never decide which one it is: a pooled track is linked
    by its own detections, and a pooled detection adds only its points within theirs (a sighting
    that spilled over two armchairs side by side once grew one over the other)."""

    point_voxel: float = 0.03
    max_points: int = 3000
    max_observations: int = 48
    overlap_radius: float = 0.08
    min_overlap: float = 0.25
    min_inside: float = 0.6
    min_cos: float = 0.85
    max_covisible: int = 1
    min_points: int = 10
    extent_percentile: float = 1.0
    recheck: bool = True
    recheck_margin: float = 0.15
    recheck_inside: float = 0.2
    recheck_min_points: int = 50
    same_overlap: float = 0.95
    pool_unconfirmed: bool = True
    #: the leading label ruled out by the object's size gives way to a runner-up it allows
    label_fit: LabelFitConfig = field(default_factory=LabelFitConfig)
    max_dormant: int = 512  # buffers of dead unconfirmed tracks kept (the oldest go first): bounded on long recordings
    seed: int = 0

    def __post_init__(self) -> None:
        if self.point_voxel <= 0 or self.max_points < 10 or self.max_observations < 1 or self.max_dormant < 0:
            raise InputError("point_voxel > 0, max_points >= 10, max_observations >= 1 and max_dormant >= 0 "
                             "are required")


@dataclass
class _Dormant:
    """The buffered detections of a track that died unconfirmed."""

    label: str
    feature: NDArray[np.float32]
    buf: list[tuple[LiftedDetection, Observation, int]]
    points: NDArray[np.float32]


@dataclass
class _ObjectState:
    id: int
    points: NDArray[np.float32]
    colors: NDArray[np.uint8]
    feature: NDArray[np.float32]
    feature_weight: float = 0.0
    votes: dict[str, float] = field(default_factory=dict)
    weak_votes: dict[str, float] = field(default_factory=dict)  # of weak candidates: name it only without votes
    observations: list[Observation] = field(default_factory=list)
    frames: set[int] = field(default_factory=set)
    hits: int = 0
    first_frame: int = 0
    last_frame: int = 0
    track_ids: list[int] = field(default_factory=list)
    positions: list[NDArray[np.float64]] = field(default_factory=list)

    @property
    def label(self) -> str:
        votes = self.votes or self.weak_votes
        return max(votes, key=lambda k: (votes[k], k)) if votes else "unknown"


def _utility(o: Observation) -> float:
    return o.score * max(o.visibility, 0.05) * float(np.sqrt(max(o.mask_area, 1))) * (0.5 if o.truncated else 1.0)


def labels_compatible(a: str, b: str) -> bool:
    return a == b or b in confusable(a)


class ObjectMemory:
    """Persistent objects fed by confirmed tracks."""

    def __init__(self, config: MemoryConfig | None = None) -> None:
        self.config = config or MemoryConfig()
        self.objects: dict[int, _ObjectState] = {}
        self._pending: dict[int, list[tuple[LiftedDetection, Observation, int]]] = {}
        self._restarted: dict[int, int] = {}  # track id -> its hits before a recheck restarted it
        self._dormant: list[_Dormant] = []  # buffers of tracks that died unconfirmed (pool_unconfirmed)
        self._inherited: dict[int, int] = {}  # track id -> detections it took over from dormant buffers
        self._next_id = 1
        self.relinks = 0  # detections moved to another object by the recheck
        self.weak_confirmed = 0  # tracks confirmed by the weak-candidate rule (``_confirms``)
        self.shape_confirmed = 0  # of those, confirmed without a confident sighting by their shape
        self.relabelled: list[str] = []  # labels changed at export by the object's size (``label_fit``)
        self._rng = np.random.default_rng(self.config.seed)

    # ---- per frame ----------------------------------------------------------------------
    def observe(self, track: Track, det: LiftedDetection, obs: Observation, frame: int,
                h_min: int, busy: set[int], rule: TrackerConfig | None = None) -> int | None:
        """Record one matched/born detection of ``track``; returns the object id once confirmed.

        ``busy`` holds objects already fed by another track in this frame: they are distinct
        from this one and cannot be re-associated with it. ``rule`` gives the confirmation of weak
        candidates (``TrackerConfig.weak_h_min``...); without it they never confirm."""
        if track.object_id is None:
            buf = self._pending.setdefault(track.id, [])
            buf.append((det, obs, frame))
            if self.config.pool_unconfirmed and self._dormant:
                self._adopt(track, det, buf)
            # buf holds the track's own detections since its (re)start and the pooled ones it took over
            confirmed = _confirms(buf, h_min, rule)
            if confirmed is None:
                return None
            # Linked by its own detections: pooled ones of a neighbour must not pull it onto that
            # neighbour (two armchairs side by side), they only help confirm it.
            inherited = self._inherited.get(track.id, 0)
            own = buf[inherited:]
            self.weak_confirmed += confirmed != "strong"
            self.shape_confirmed += confirmed == "shape"
            place = self._same_place(own or buf, busy) if confirmed != "strong" else None
            if place is not None:
                self.objects[place].track_ids.append(track.id)
            oid = place if place is not None else self._link(track, own or buf, busy)
            track.object_id = oid
            self._restarted.pop(track.id, None)
            self._inherited.pop(track.id, None)
            for k, (d, o, f) in enumerate(self._pending.pop(track.id)):
                self._add(self.objects[oid], self._within(d, own) if k < inherited else d, o, f)
            return oid
        obj = self.objects[track.object_id]
        if self.config.recheck and self._inconsistent(det.points, obj.points):
            self.relinks += 1
            obj.track_ids.remove(track.id)
            other = self._match(track, [(det, obs, frame)], busy | {obj.id})
            if other is None:
                # Nothing known is there: confirmed afresh, like any track's first detections.
                track.object_id = None
                self._pending[track.id] = [(det, obs, frame)]
                self._restarted[track.id] = track.hits - 1
                return None
            self.objects[other].track_ids.append(track.id)
            track.object_id = other
            obj = self.objects[other]
        self._add(obj, det, obs, frame)
        return track.object_id

    def _same_place(self, buf: list[tuple[LiftedDetection, Observation, int]], busy: set[int]) -> int | None:
        """The object whose points hold most of ``buf``'s points (``min_overlap`` x 2 of them within
        ``overlap_radius``), unless they stand on it: a place confirmed by weak candidates that
        a confident object already occupies is that object (a weak sighting never outvotes it)."""
        pts = np.concatenate([d.points for d, _, _ in buf]) if buf else np.zeros((0, 3), np.float32)
        if len(pts) == 0:
            return None
        r = self.config.overlap_radius
        best, best_near = None, min(1.0, 2.0 * self.config.min_overlap)
        for obj in self.objects.values():
            if obj.id in busy or len(obj.points) == 0:
                continue
            lo, hi = obj.points.min(axis=0) - r, obj.points.max(axis=0) + r
            if np.any(pts.min(axis=0) > hi) or np.any(pts.max(axis=0) < lo):
                continue
            d, _ = cKDTree(obj.points).query(pts, distance_upper_bound=r)
            near = float(np.isfinite(d).mean())
            if near >= best_near and not stands_on(pts, obj.points):
                best, best_near = obj.id, near
        return best

    def _within(self, det: LiftedDetection, own: list[tuple[LiftedDetection, Observation, int]]) -> LiftedDetection:
        """A pooled detection's points within the track's own detections' box (``recheck_margin``
        around it): a sighting that spilled onto a neighbour adds only this thing's surface."""
        pts = [d.points for d, _, _ in own if len(d.points)]
        if not pts or not len(det.points):
            return det
        ref = np.concatenate(pts)
        m = self.config.recheck_margin
        keep = np.all((det.points >= ref.min(axis=0) - m) & (det.points <= ref.max(axis=0) + m), axis=1)
        return replace(det, points=det.points[keep], colors=det.colors[keep])

    def _inconsistent(self, pts: NDArray[np.float32], ref: NDArray[np.float32]) -> bool:
        cfg = self.config
        if len(ref) < cfg.recheck_min_points or len(pts) < 10:
            return False
        m = cfg.recheck_margin
        lo, hi = ref.min(axis=0) - m, ref.max(axis=0) + m
        if float(np.all((pts >= lo) & (pts <= hi), axis=1).mean()) >= cfg.recheck_inside:
            return False
        d, _ = cKDTree(ref).query(pts, distance_upper_bound=cfg.overlap_radius)
        return float(np.isfinite(d).mean()) < 0.05

    def drop(self, track: Track) -> None:
        """A track died: objects stay; its unconfirmed detections wait for a later track of the same
        thing (``pool_unconfirmed``; else they are forgotten)."""
        buf = self._pending.pop(track.id, None)
        self._restarted.pop(track.id, None)
        self._inherited.pop(track.id, None)
        if buf and self.config.pool_unconfirmed and track.object_id is None:
            pts = np.concatenate([d.points for d, _, _ in buf])
            if len(pts):
                feat = np.mean([d.descriptor for d, _, _ in buf], axis=0).astype(np.float32)
                self._dormant.append(_Dormant(track.label, feat, buf, pts))
                del self._dormant[: max(0, len(self._dormant) - self.config.max_dormant)]

    def _adopt(self, track: Track, det: LiftedDetection, buf: list[tuple[LiftedDetection, Observation, int]]
               ) -> None:
        """Move into ``buf`` (before its detections) the dormant buffers ``det`` overlaps in 3D with a
        compatible label or descriptor; their detections count as the track's hits."""
        pts = det.points
        if len(pts) == 0:
            return
        r = self.config.overlap_radius
        lo, hi = pts.min(axis=0) - r, pts.max(axis=0) + r
        keep: list[_Dormant] = []
        taken: list[tuple[LiftedDetection, Observation, int]] = []
        for dm in self._dormant:
            if (np.any(dm.points.min(axis=0) > hi) or np.any(dm.points.max(axis=0) < lo)
                    or not self._same_kind(track.label, det.descriptor, dm)
                    or max(self._overlap(pts, dm.points), self._overlap(dm.points, pts)) == 0.0):
                keep.append(dm)
                continue
            taken += dm.buf
        if taken:
            self._dormant = keep
            buf[:0] = taken
            self._inherited[track.id] = self._inherited.get(track.id, 0) + len(taken)

    def _same_kind(self, label: str, feat: NDArray[np.floating], dm: _Dormant) -> bool:
        if labels_compatible(label, dm.label):
            return True
        na, nb = float(np.linalg.norm(feat)), float(np.linalg.norm(dm.feature))
        return na > 0 and nb > 0 and float(np.dot(feat, dm.feature)) / (na * nb) >= self.config.min_cos

    def _link(self, track: Track, buf: list[tuple[LiftedDetection, Observation, int]], busy: set[int]) -> int:
        """The object ``buf``'s detections belong to: the best overlapping compatible one, else a new one."""
        best = self._match(track, buf, busy)
        if best is not None:
            self.objects[best].track_ids.append(track.id)
            return best
        oid = self._next_id
        self._next_id += 1
        self.objects[oid] = _ObjectState(id=oid, points=np.zeros((0, 3), np.float32),
                                         colors=np.zeros((0, 3), np.uint8),
                                         feature=np.zeros_like(track.feature), track_ids=[track.id])
        return oid

    def _match(self, track: Track, buf: list[tuple[LiftedDetection, Observation, int]], busy: set[int]
               ) -> int | None:
        pts = np.concatenate([d.points for d, _, _ in buf]) if buf else np.zeros((0, 3), np.float32)
        feat = np.mean([d.descriptor for d, _, _ in buf], axis=0) if buf else track.feature
        best, best_score = None, 0.0
        for obj in self.objects.values():
            if obj.id in busy or len(obj.points) == 0 or len(pts) == 0:
                continue
            if not self._compatible(track.label, feat, obj):
                continue
            score = self._overlap(pts, obj.points)
            if score > best_score:
                best, best_score = obj.id, score
        return best

    def _compatible(self, label: str, feat: NDArray[np.floating], obj: _ObjectState) -> bool:
        if labels_compatible(label, obj.label) or label in obj.votes or label in obj.weak_votes:
            return True
        na, nb = float(np.linalg.norm(feat)), float(np.linalg.norm(obj.feature))
        return na > 0 and nb > 0 and float(np.dot(feat, obj.feature)) / (na * nb) >= self.config.min_cos

    def _overlap(self, pts: NDArray[np.float32], ref: NDArray[np.float32]) -> float:
        """Re-association score in [0, 2]; 0 when neither overlap criterion is met."""
        cfg = self.config
        r = cfg.overlap_radius
        lo, hi = ref.min(axis=0) - r, ref.max(axis=0) + r
        inside = float(np.all((pts >= lo) & (pts <= hi), axis=1).mean())
        if inside == 0.0:
            return 0.0
        d, _ = cKDTree(ref).query(pts, distance_upper_bound=r)
        near = float(np.isfinite(d).mean())
        if near >= cfg.min_overlap or inside >= cfg.min_inside:
            return near + inside
        return 0.0

    def _add(self, obj: _ObjectState, det: LiftedDetection, obs: Observation, frame: int) -> None:
        cfg = self.config
        w = float(det.detection.score)
        support = vote_weight(det)  # votes weigh confidence x m² of surface, not one per box
        votes = obj.weak_votes if det.detection.weak else obj.votes
        for label, v in det.detection.label_votes().items():
            votes[label] = votes.get(label, 0.0) + v * support
        obj.feature = ((obj.feature * obj.feature_weight + det.descriptor * w) / (obj.feature_weight + w)).astype(
            np.float32)
        obj.feature_weight += w
        obj.hits += 1
        obj.first_frame = frame if obj.hits == 1 else min(obj.first_frame, frame)
        obj.last_frame = max(obj.last_frame, frame)
        obj.frames.add(frame)
        obj.positions.append(det.position)
        obj.observations.append(obs)
        if len(obj.observations) > cfg.max_observations:
            worst = min(range(len(obj.observations)), key=lambda k: (_utility(obj.observations[k]), k))
            obj.observations.pop(worst)
        if len(det.points):
            self._add_points(obj, det.points, det.colors)

    def _add_points(self, obj: _ObjectState, pts: NDArray[np.float32], cols: NDArray[np.uint8]) -> None:
        cfg = self.config
        allp = np.concatenate([obj.points, pts.astype(np.float32)])
        allc = np.concatenate([obj.colors, cols.astype(np.uint8)])
        ijk = np.floor(allp / cfg.point_voxel).astype(np.int64) + (1 << 20)
        keys = (ijk[:, 0] << 42) | (ijk[:, 1] << 21) | ijk[:, 2]
        _, first = np.unique(keys, return_index=True)
        first.sort()
        if len(first) > cfg.max_points:
            first = np.sort(self._rng.choice(first, cfg.max_points, replace=False))
        obj.points, obj.colors = allp[first], allc[first]

    # ---- end of mapping -----------------------------------------------------------------
    def observed_frames(self) -> set[int]:
        """The frames the kept and the buffered observations refer to."""
        out = {o.frame_index for obj in self.objects.values() for o in obj.observations}
        out |= {f for buf in self._pending.values() for _, _, f in buf}
        out |= {f for dm in self._dormant for _, _, f in dm.buf}
        return out

    def carve(self, views: DepthViews) -> int:
        """Drop each object's points that its own boxes, in the views that see them, contradict
        (``box_carving``); returns how many points went."""
        gone = 0
        for obj in self.objects.values():
            keep = carve(obj.points, [(o.frame_index, o.box) for o in obj.observations], views)
            if not keep.all():
                gone += int((~keep).sum())
                obj.points, obj.colors = obj.points[keep], obj.colors[keep]
        return gone

    def merge_duplicates(self) -> int:
        """Merge objects that overlap in 3D with compatible labels, best pair first; returns how
        many were merged. Only pairs whose boxes (grown by ``overlap_radius``) intersect are scored,
        and after a merge only the pairs of the grown object are re-scored."""
        r = self.config.overlap_radius
        bounds = {k: (o.points.min(axis=0) - r, o.points.max(axis=0) + r)
                  for k, o in self.objects.items() if len(o.points)}
        scores: dict[tuple[int, int], float] = {}

        def score(a: int, b: int) -> None:
            scores.pop((a, b), None)
            if a not in bounds or b not in bounds:
                return
            (la, ha), (lb, hb) = bounds[a], bounds[b]
            if np.any(la > hb) or np.any(lb > ha):
                return
            s = self._pair_score(self.objects[a], self.objects[b])
            if s > 0:
                scores[(a, b)] = s

        ids = sorted(bounds)
        for i, a in enumerate(ids):
            for b in ids[i + 1:]:
                score(a, b)
        merged = 0
        while scores:
            (a, b), _ = max(scores.items(), key=lambda kv: (kv[1], -kv[0][0], -kv[0][1]))
            keep, gone = (a, b) if len(self.objects[a].points) >= len(self.objects[b].points) else (b, a)
            self._absorb(self.objects[keep], self.objects.pop(gone))
            bounds.pop(gone)
            pts = self.objects[keep].points
            bounds[keep] = (pts.min(axis=0) - r, pts.max(axis=0) + r)
            scores = {k: v for k, v in scores.items() if gone not in k and keep not in k}
            for other in sorted(bounds):
                if other != keep:
                    score(min(keep, other), max(keep, other))
            merged += 1
        return merged

    def _pair_score(self, oa: _ObjectState, ob: _ObjectState) -> float:
        cfg = self.config
        small, big = (oa, ob) if len(oa.points) <= len(ob.points) else (ob, oa)
        if cfg.same_overlap <= 1.0 and len(small.points) and len(big.points):
            d, _ = cKDTree(big.points).query(small.points, distance_upper_bound=cfg.overlap_radius)
            near = float(np.isfinite(d).mean())
            # One thing, whatever the labels and however often seen together; unless the smaller
            # stands on the larger (a bowl on a desk is within centimetres of its top everywhere).
            if near >= cfg.same_overlap and not stands_on(small.points, big.points):
                return 1.0 + near
        if len(oa.frames & ob.frames) > cfg.max_covisible:
            return 0.0
        if not (labels_compatible(oa.label, ob.label) or self._cos(oa, ob) >= cfg.min_cos):
            return 0.0
        small, big = (oa, ob) if len(oa.points) <= len(ob.points) else (ob, oa)
        return self._overlap(small.points, big.points)

    @staticmethod
    def _cos(a: _ObjectState, b: _ObjectState) -> float:
        na, nb = float(np.linalg.norm(a.feature)), float(np.linalg.norm(b.feature))
        return float(np.dot(a.feature, b.feature)) / (na * nb) if na > 0 and nb > 0 else 0.0

    def _absorb(self, keep: _ObjectState, gone: _ObjectState) -> None:
        for k, v in gone.votes.items():
            keep.votes[k] = keep.votes.get(k, 0.0) + v
        for k, v in gone.weak_votes.items():
            keep.weak_votes[k] = keep.weak_votes.get(k, 0.0) + v
        tw = keep.feature_weight + gone.feature_weight
        if tw > 0:
            keep.feature = ((keep.feature * keep.feature_weight + gone.feature * gone.feature_weight) / tw).astype(
                np.float32)
        keep.feature_weight = tw
        keep.hits += gone.hits
        keep.first_frame = min(keep.first_frame, gone.first_frame)
        keep.last_frame = max(keep.last_frame, gone.last_frame)
        keep.frames |= gone.frames
        keep.track_ids += gone.track_ids
        keep.positions += gone.positions
        obs = sorted(keep.observations + gone.observations, key=lambda o: (-_utility(o), o.frame_index))
        keep.observations = sorted(obs[: self.config.max_observations], key=lambda o: o.frame_index)
        self._add_points(keep, gone.points, gone.colors)

    def export(self) -> list[MapObject]:
        """``MapObject``s in id order, renumbered 1..n; objects with too few points are dropped."""
        out: list[MapObject] = []
        self.relabelled = []
        for obj in sorted(self.objects.values(), key=lambda o: o.id):
            if len(obj.points) < self.config.min_points:
                continue
            out.append(self._to_map_object(obj, len(out) + 1))
        return out

    def _to_map_object(self, obj: _ObjectState, new_id: int) -> MapObject:
        lo, hi, fp = object_box(obj.points, self.config.extent_percentile)
        label = obj.label
        fitted, why = fitting_label(obj.votes or obj.weak_votes, obj.points, self.config.label_fit)
        if fitted is not None:
            label = fitted
            self.relabelled.append(f"object {new_id}: {why}")
        cat = BY_NAME.get(label)
        mo = MapObject(
            id=new_id, label=label, label_votes=dict(sorted((obj.votes or obj.weak_votes).items())),
            position=(lo + hi) / 2.0,
            extent_min=lo, extent_max=hi, footprint=fp, points=obj.points.copy(), colors=obj.colors.copy(),
            feature=obj.feature.copy(), hits=obj.hits, first_frame=obj.first_frame, last_frame=obj.last_frame,
            observations=sorted(obj.observations, key=lambda o: o.frame_index),
        )
        mo.category_id = cat.id if cat else 0
        mo.track_ids = list(obj.track_ids)
        return mo


def _confirms(buf: list[tuple[LiftedDetection, Observation, int]], h_min: int, rule: TrackerConfig | None
              ) -> str | None:
    """"strong" when ``h_min`` of the sightings are confident detections; "weak" when, with weak
    candidates among them, there are ``rule.weak_h_min`` sightings (``rule.weak_confident`` of them
    confident) whose leading label's summed
    score is at least ``rule.weak_score`` and ``rule.weak_agreement`` of all their label scores;
    "shape" when such sightings lack the confident ones but their points have the leading label's
    shape from several camera places (``rule.weak_shape``, ``corroborate.corroborated``); else
    None (not yet an object)."""
    confident = sum(not d.detection.weak for d, _, _ in buf)
    if confident >= h_min:
        return "strong"
    if rule is None or not rule.weak_h_min or len(buf) < max(rule.weak_h_min, h_min):
        return None
    if confident < rule.weak_confident and not rule.weak_shape:
        return None
    votes: dict[str, float] = {}
    for d, _, _ in buf:
        for label, v in d.detection.label_votes().items():
            votes[label] = votes.get(label, 0.0) + v
    if not votes:
        return None
    best = max(votes, key=lambda k: (votes[k], k))
    lead = votes[best]
    if lead < rule.weak_score or lead < rule.weak_agreement * sum(votes.values()):
        return None
    if confident >= rule.weak_confident:
        return "weak"
    if corroborated(best, [d.points for d, _, _ in buf], [d.camera for d, _, _ in buf]):
        return "shape"
    return None


def object_box(points: NDArray[np.floating], percentile: float
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """An object's robust box (``percentile`` .. 100 - ``percentile`` of its points per axis) and
    footprint. The footprint is the hull of the points inside that box: a few stray points (mask
    edges on the floor or a neighbour) would otherwise stretch the hull, and goals picked at reach
    distance from it would end up out of reach of the real object."""
    p = np.asarray(points, dtype=np.float64)
    lo, hi = np.percentile(p, percentile, axis=0), np.percentile(p, 100.0 - percentile, axis=0)
    inside = np.all((p[:, :2] >= lo[:2]) & (p[:, :2] <= hi[:2]), axis=1)
    return lo, hi, footprint(p[inside, :2] if inside.sum() >= 3 else p[:, :2])


def footprint(xy: NDArray[np.float64]) -> NDArray[np.float64]:
    """Counter-clockwise convex hull (K, 2) of x, y points; the bounding rectangle when degenerate."""
    if len(xy) >= 3:
        try:
            hull = ConvexHull(xy)
            return np.asarray(xy[hull.vertices], dtype=np.float64)
        except QhullError:
            pass
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    return np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]], dtype=np.float64)
