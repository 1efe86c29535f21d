"""The search's own map: the robot's frames mapped as it goes, set beside the saved map for the retriever.

A search must answer the request as ``capnav query`` would, with what the robot has seen since:
"the smallest cabinet" compares every cabinet known, "the plant next to the washing machine"
needs that washing machine seen. So every frame the search looks at is fused by a ``Mapper`` of
its own (the detections the search already made, not a second detector run), and the saved map's
objects are checked against the frame's depth as a map update checks them
(``mapping.update``: their points seen again, or seen through). A snapshot is a map for the
retriever: the saved map's objects that were not seen gone, plus the objects the robot saw that no
saved object explains (none of its label whose points they overlap, in its main colour), captioned
by the offline captioner and embedded with the retriever's embedder. Nothing here reads a
simulator's truth: frames, detections and the saved map only.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from capnav.core.frame import Frame
from capnav.core.lazy import lazy_module
from capnav.language import context, purpose
from capnav.language.context import canonical_label
from capnav.language.embedder import TextEmbedder
from capnav.language.offline_captioner import ObservationCaptioner
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.mapper import Mapper, MapperConfig
from capnav.mapping.objects import MapObject
from capnav.mapping.tracker import TrackerConfig
from capnav.mapping.update import UpdateConfig
from capnav.perception.base import Detection, Detector

E_ = lazy_module("capnav.mapping._evidence")
U_ = lazy_module("capnav.mapping.update")


@dataclass(frozen=True)
class LiveMapConfig:
    """``min_hits``: detections a seen object needs to be asked about (two views: one confused view
    is not an object); ``colour_distance``: CIEDE2000 (kL 2) between main colours within which a
    seen object at a saved one's place is that one; ``update``: the map update's evidence rules
    (an object seen through in enough frames is gone)."""

    min_hits: int = 2
    colour_distance: float = 20.0
    update: UpdateConfig = field(default_factory=UpdateConfig)


@dataclass
class Snapshot:
    """The map the retriever is asked on, and what each of its objects is to the search."""

    cmap: CapNavMap
    seen_new: dict[int, MapObject]  # composite id -> an object seen that the saved map does not explain
    confirmed: set[int]  # saved objects seen again at their place
    gone: set[int]  # saved objects seen gone (left out of ``cmap``)
    signature: tuple[Any, ...]  # equal signatures: the retriever would answer the same


class _Replay(Detector):
    """A detector that hands the mapper the detections the search already made for this frame."""

    def __init__(self, inner: Any) -> None:
        self.id = str(getattr(inner, "id", "replay"))
        self.needs_truth = False
        self.labels = getattr(inner, "labels", None)
        self.dets: list[Detection] = []

    def detect(self, frame: Frame) -> list[Detection]:
        return self.dets


class LiveMap:
    """The robot's frames mapped beside ``cmap`` (the saved map), for re-asking the retriever."""

    def __init__(self, cmap: CapNavMap, detector: Any, embedder: TextEmbedder,
                 config: LiveMapConfig | None = None) -> None:
        from capnav.perception import create_encoder

        self.cmap, self.embedder = cmap, embedder
        self.config = cfg = config or LiveMapConfig()
        self._replay = _Replay(detector)
        mcfg = MapperConfig(tracker=replace(TrackerConfig(), h_min=cfg.min_hits))
        mcfg.carve = replace(mcfg.carve, enabled=False)  # snapshots are taken mid-stream
        self.mapper = Mapper(mcfg, self._replay, create_encoder("label-embedding", embedder=embedder))
        self.captioner = ObservationCaptioner()
        self.old = list(cmap.objects)
        self._ev = U_._object_evidence(self.old, cfg.update)
        self.absent: set[int] = set()  # saved objects looked for at their place and not seen there
        #: The labels worth mapping (the request's target and landmarks; None: all). Lifting a
        #: detection onto its support costs most of a frame, and nothing else changes the answer.
        self.kinds: set[str] | None = None
        self.frames = 0
        self._captions: dict[tuple[Any, ...], tuple[str, str, np.ndarray]] = {}
        self._context_store: dict[str, Any] = {}
        self._main_colour: dict[int, np.ndarray | None] = {}

    def add(self, frame: Frame, detections: list[Detection]) -> None:
        """Fuse one frame the search looked at, with the detections it made on it."""
        cfg = self.config.update
        kinds = self.kinds
        self._replay.dets = [d for d in detections if kinds is None or canonical_label(d.label) in kinds]
        self.mapper.integrate(frame)
        self.frames += 1
        ev = self._ev
        if not len(ev.points):
            return
        Twc = np.asarray(frame.T_wc, dtype=np.float64)
        K = frame.K
        depth = np.ascontiguousarray(frame.depth, dtype=np.float32)
        codes = E_.classify_points(ev.points, np.linalg.inv(Twc), K.fx, K.fy, K.cx, K.cy, depth, cfg.near, cfg.far,
                                   cfg.tol, cfg.margin)
        seen = np.bincount(ev.owner[codes == E_.SEEN], minlength=ev.n)
        thr = np.bincount(ev.owner[codes == E_.THROUGH], minlength=ev.n)
        spoke = seen + thr >= cfg.min_points
        ev.empty += spoke & (thr >= cfg.empty_share * (seen + thr))
        ev.present += spoke & (seen >= cfg.present_share * (seen + thr))

    # ------------------------------------------------------------------ the snapshot
    def seen_objects(self) -> list[MapObject]:
        """The objects of the robot's own frames so far (duplicates merged, on a copy: the mapper
        goes on), with at least ``min_hits`` detections."""
        memory = copy.deepcopy(self.mapper.memory)
        memory.merge_duplicates()
        return [o for o in memory.export() if o.hits >= self.config.min_hits]

    def snapshot(self) -> Snapshot:
        cfg = self.config
        seen = self.seen_objects()
        ev = self._ev
        gone_q = (ev.empty >= cfg.update.min_empty_frames) & (ev.empty >= 2 * ev.present)
        confirmed: set[int] = set()
        unexplained: list[MapObject] = []
        for n in seen:
            q = self._explained_by(n)
            if q is None:
                unexplained.append(n)
            else:
                confirmed.add(self.old[q].id)
        # A saved object with a newcomer of its kind on its place is not there any more.
        for n in unexplained:
            for q, o in enumerate(self.old):
                if U_._compatible(n, o) and U_._overlap(n, o, cfg.update.same_radius) >= cfg.update.same_overlap:
                    gone_q[q] = True
        gone = {o.id for q, o in enumerate(self.old) if (gone_q[q] or o.id in self.absent) and o.id not in confirmed}
        keep = [o for o in self.old if o.id not in gone]
        base = max([o.id for o in self.old] + [o.id for o in self.cmap.retired], default=0) + 1
        news: dict[int, MapObject] = {}
        for k, n in enumerate(unexplained):
            m = copy.copy(n)
            m.id = base + k
            news[m.id] = m
        objects = keep + list(news.values())
        occ = self.cmap.occupancy
        caches: dict[str, Any] = {"attributes": dict(self.cmap.caches.get("attributes", {})),
                                  context.CACHE_KEY: self._context_store}
        if purpose.CACHE_KEY in self.cmap.caches:  # the glosses of requests by purpose, embedded once
            caches[purpose.CACHE_KEY] = self.cmap.caches[purpose.CACHE_KEY]
        self._describe(list(news.values()), objects, caches)
        meta = {k: v for k, v in self.cmap.meta.items() if k not in ("recordings", "updates")}
        live = CapNavMap(objects=objects, voxels=self.cmap.voxels, occupancy=occ, meta=meta, caches=caches,
                         trajectory=None, retired=[])
        sig = (tuple(sorted(gone)), tuple(sorted(confirmed)),
               tuple(sorted((n.label, round(float(n.position[0]) * 2), round(float(n.position[1]) * 2),
                             n.caption or "") for n in news.values())))
        return Snapshot(live, news, confirmed, gone, sig)

    def _explained_by(self, n: MapObject) -> int | None:
        """The saved object ``n`` is: one of a compatible label whose points it overlaps, in its main
        colour (a new colour on a saved object's place is something new standing there)."""
        u = self.config.update
        best, best_ov = None, 0.0
        for q, o in enumerate(self.old):
            if not U_._compatible(n, o):
                continue
            ov = U_._overlap(n, o, max(u.same_radius, 0.15))
            if ov >= u.same_overlap and ov > best_ov and self._same_colour(n, o):
                best, best_ov = q, ov
        return best

    def _same_colour(self, n: MapObject, o: MapObject) -> bool:
        from capnav.core.colour import ciede2000

        a, b = self._main(n, cache=False), self._main(o)
        if a is None or b is None:
            return True  # nothing to tell them apart by
        return float(ciede2000(a, b, kL=2.0)) <= self.config.colour_distance

    def _main(self, o: MapObject, cache: bool = True) -> np.ndarray | None:
        from capnav.language.colors import object_colors

        if cache and o.id in self._main_colour:
            return self._main_colour[o.id]
        cols = object_colors(np.asarray(o.colors).reshape(-1, 3)) if len(o.colors) else []
        out = np.asarray(cols[0].lab) if cols else None
        if cache:
            self._main_colour[o.id] = out
        return out

    def _describe(self, news: list[MapObject], objects: list[MapObject], caches: dict[str, Any]) -> None:
        """Captions, embeddings and observed attributes of the newly seen objects (the saved
        objects keep theirs); a caption is embedded once per distinct text."""
        if not news:
            return
        scene = context.SceneContext(objects, self.cmap.occupancy, store=caches[context.CACHE_KEY])
        namer = self.captioner
        todo: list[tuple[MapObject, str, str]] = []
        for o in news:
            cap = namer.caption(o, scene)
            todo.append((o, cap.text, cap.source))
        texts = sorted({t for _, t, _ in todo if (t,) not in self._captions})
        if texts:
            for t, v in zip(texts, self.embedder.embed(texts), strict=True):
                self._captions[(t,)] = (t, "", np.asarray(v, dtype=np.float32))
        attrs = caches["attributes"]
        for o, text, source in todo:
            o.caption, o.caption_source = text, source
            o.embedding = self._captions[(text,)][2].copy()
            o.embedding_model = self.embedder.model_id
            attrs[str(o.id)] = {key: [[c.name, *[round(v, 3) for v in c.lab], round(c.fraction, 4),
                                       round(c.distance, 3)] for c in cols]
                                for key, cols in (("colors", namer.colors(o)), ("base_colors", namer.base_colors(o)))}
            attrs[str(o.id)]["shapes"] = namer.shapes(o)
            attrs[str(o.id)]["surface"] = namer.surface(o).to_list()
