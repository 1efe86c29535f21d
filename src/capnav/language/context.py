"""What the map itself says about an object's surroundings: neighbours, relative size and the room.

Room names are never observed, so a room is inferred from characteristic objects (fridge / stove /
counter -> kitchen, bed -> bedroom, toilet / bathtub -> bathroom, sofa / TV -> living room,
desk -> office). Each cue counts with its weight times a Gaussian of the walking distance: with an
occupancy grid a geodesic through free space and furniture but not through walls
(``rooms.geodesic_from_boxes``), without one the straight-line distance when no wall lies between.
Walls are occupied cells of the top-down grid that no object's box covers. The strongest cue per
room type wins (the nearest stove says "kitchen"; ten armchairs do not add up).
Used by the offline captioner ("next to the bed", "in the kitchen") and by retrieval predicates.

The walls and rooms (line of sight, room scores, room regions: geodesics over the whole grid,
about 1 s for 300 objects) are computed at caption time and kept in the map (``cmap.caches
["context"]``, see ``SceneContext.store``) under a digest of everything they depend on: the
objects' labels and boxes, the grid, the configuration and this module's and ``rooms.py``'s
source, so a changed map or rule recomputes them and a stored result is never stale.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import NAMES, category
from capnav.core.errors import InputError
from capnav.core.grid import OCCUPIED, OccupancyGrid
from capnav.language.lexicon import load_lexicon
from capnav.mapping.objects import MapObject

#: Characteristic objects per room type and how strongly each one implies the room.
ROOM_CUES: dict[str, dict[str, float]] = {
    "kitchen": {"refrigerator": 1.0, "stove": 1.0, "counter": 0.9, "washing machine": 0.3},
    "bedroom": {"bed": 1.0, "nightstand": 0.7, "wardrobe": 0.5, "dresser": 0.5},
    "bathroom": {"toilet": 1.0, "bathtub": 1.0, "sink": 0.6, "washing machine": 0.3},
    "living room": {"sofa": 1.0, "tv": 0.8, "coffee table": 0.8, "armchair": 0.5},
    "office": {"desk": 1.0, "bookshelf": 0.4},
}
#: The room type without characteristic objects: requested by name, recognised as no typed room.
HALLWAY = "hallway"
#: Room words: WordNet's (the lexicon's ``rooms``: "guest room", "kitchenette", "powder room",
#: "kid's room") and these, which WordNet lacks or files elsewhere ("lounge" is a sofa first
#: there, "family room" and "living area" are not in it).
_OWN_ROOM_WORDS: dict[str, str] = {
    "kitchen": "kitchen", "bedroom": "bedroom", "bed room": "bedroom", "master bedroom": "bedroom",
    "bathroom": "bathroom", "bath room": "bathroom", "restroom": "bathroom", "washroom": "bathroom",
    "living room": "living room", "lounge": "living room", "sitting room": "living room",
    "living area": "living room", "family room": "living room",
    "office": "office", "study": "office", "home office": "office", "workroom": "office",
    # No object marks a hallway: it is a region where no room's cues stand (see ``SceneContext._room``).
    "hallway": HALLWAY, "hall": HALLWAY, "corridor": HALLWAY, "entrance hall": HALLWAY, "entryway": HALLWAY,
    "hall way": HALLWAY, "passage": HALLWAY, "passageway": HALLWAY, "foyer": HALLWAY, "landing": HALLWAY,
}
ROOM_SYNONYMS: dict[str, str] = {**load_lexicon().rooms, **_OWN_ROOM_WORDS}
# The regular reading drops a possessive "'s" before it looks for room words ("kid room").
ROOM_SYNONYMS.update({k.replace("'s", ""): v for k, v in ROOM_SYNONYMS.items() if "'s" in k})
#: The most words a room name has ("children's room" is three tokens: children 's room).
ROOM_MAX_WORDS = 4


def _room_key(words: list[str]) -> str:
    """Words joined as the room names are written: a possessive the tokenizer split off is put
    back on its word ("kid 's room" -> "kid's room")."""
    return " ".join(words).replace(" 's ", "'s ").replace(" ' ", "' ")


def rooms_starting(words: list[str], i: int) -> Iterator[tuple[str, int]]:
    """(room type, number of words) of every room name starting at word ``i``, longest first
    ("hall way", then "hall"), for a reader that checks more than the words."""
    for n in range(min(ROOM_MAX_WORDS, len(words) - i), 0, -1):
        room = ROOM_SYNONYMS.get(_room_key(words[i:i + n]))
        if room is not None:
            yield room, n


def room_starting(words: list[str], i: int) -> tuple[str, int] | None:
    """(room type, number of words) of the longest room name starting at word ``i``."""
    return next(rooms_starting(words, i), None)


def room_ending(words: list[str], j: int) -> tuple[str, int] | None:
    """(room type, number of words) of the longest room name ending just before word ``j``."""
    for n in range(min(ROOM_MAX_WORDS, j), 0, -1):
        room = ROOM_SYNONYMS.get(_room_key(words[j - n:j]))
        if room is not None:
            return room, n
    return None


@dataclass(frozen=True)
class ContextConfig:
    next_to_distance: float = 1.2  # m between footprints for "next to"
    room_sigma: float = 2.5  # m, Gaussian fall-off of a room cue
    room_min_score: float = 0.35  # below this the room stays unknown
    wall_cells: int = 1  # occupied non-object cells on a segment that count as a wall
    object_margin: float = 0.15  # m around object boxes not counted as wall
    los_range: float = 3.0  # m of box gap up to which walls between objects are checked
    door_width: float = 1.0  # m: interior doorways are narrower, so eroding by half of it parts the rooms
    min_room_m2: float = 1.0  # m² of eroded core below which a region is not a room of its own
    region_strong: float = 0.9  # noisy-or cue score above which a region clearly is that room type
    open_plan_ratio: float = 0.75  # second room type's cue weight over the first's for an open plan
    # A region is a room type when P(type | what stands in it) reaches this (``room_prior``; 0.8 is
    # four to one): a sink alone (kitchen or bathroom) is no room, a sink with a stove a kitchen.
    room_confidence: float = 0.8


#: ``CapNavMap.caches`` key of the stored walls and rooms (written by ``describe_map``).
CACHE_KEY = "context"
_SOURCES = (Path(__file__), Path(__file__).with_name("rooms.py"), Path(__file__).with_name("room_prior.py"))


def canonical_label(label: str) -> str:
    """A category name canonicalised through the vocabulary's synonyms, else as given."""
    try:
        return category(label).name
    except InputError:
        return label.strip().lower()


def label_of(obj: MapObject) -> str:
    return canonical_label(obj.label)


@dataclass
class SceneContext:
    """Spatial relations between all objects of a map, computed once (vectorised)."""

    objects: list[MapObject]
    occupancy: OccupancyGrid | None = None
    config: ContextConfig = field(default_factory=ContextConfig)
    #: A map's ``caches["context"]``: walls and rooms are read from it when its digest matches,
    #: else computed and written to it (None: always computed, nothing kept).
    store: dict[str, Any] | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        n = len(self.objects)
        self.labels = [label_of(o) for o in self.objects]
        self.index = {o.id: i for i, o in enumerate(self.objects)}
        self.lo = np.array([o.extent_min[:2] for o in self.objects], dtype=np.float64).reshape(n, 2)
        self.hi = np.array([o.extent_max[:2] for o in self.objects], dtype=np.float64).reshape(n, 2)
        self.xy = np.array([o.position[:2] for o in self.objects], dtype=np.float64).reshape(n, 2)
        size = np.array([o.size for o in self.objects], dtype=np.float64).reshape(n, 3)
        self.volume = np.prod(np.maximum(size, 0.02), axis=1)
        self.height = np.maximum(size[:, 2], 0.02)
        self.width = np.maximum(np.max(size[:, :2], axis=1), 0.02)  # the footprint's longer side
        # Box-to-box gap in the floor plane (0 when boxes touch or overlap).
        gap = np.maximum(0.0, np.maximum(self.lo[:, None] - self.hi[None], self.lo[None] - self.hi[:, None]))
        self.gap = np.hypot(gap[..., 0], gap[..., 1])
        self.region = np.full(n, -1, dtype=np.int64)  # room region per object (-1: no walls known)
        self.region_rooms: dict[int, tuple[str | None, dict[str, float]]] = {}
        self.open_plan: set[int] = set()  # regions whose type is decided per object (two rooms' cues)
        self.region_confidence: dict[int, float] = {}  # posterior of each region's most probable type
        digest = self._digest()
        if not (self.store is not None and digest and self.store.get("digest") == digest and self._restore(self.store)):
            self.visible = self._line_of_sight()
            self.room_score = self._room_scores()
            if self.occupancy is not None and n:
                self._regions()
            if self.store is not None:
                self.store.clear()
                self.store.update(self._stored(digest))
        self.rooms = [self._room(i) for i in range(n)]

    # -- the stored walls and rooms ------------------------------------------------------------
    def _digest(self) -> str:
        """sha256 of every input of the walls and rooms, and of the code that computes them."""
        h = hashlib.sha256()
        for src in _SOURCES:
            try:
                h.update(src.read_bytes())
            except OSError:  # no source to key on (a bytecode-only install): never read the store
                return ""
        h.update(json.dumps([dataclasses.asdict(self.config), self.labels, [o.id for o in self.objects]]).encode())
        for a in (self.lo, self.hi, self.xy):
            h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
        if self.occupancy is not None:
            h.update(json.dumps(self.occupancy.spec.to_dict(), sort_keys=True).encode())
            h.update(np.ascontiguousarray(self.occupancy.cells).tobytes())
        return h.hexdigest()

    def _stored(self, digest: str) -> dict[str, Any]:
        """JSON-able walls and rooms (floats round-trip exactly through JSON)."""
        blocked = np.argwhere(np.triu(~self.visible, k=1))
        return {"digest": digest, "blocked": blocked.tolist(), "room_score": self.room_score.tolist(),
                "region": self.region.tolist(), "open_plan": sorted(self.open_plan),
                "region_confidence": {str(k): v for k, v in self.region_confidence.items()},
                "region_rooms": {str(k): [room, scores] for k, (room, scores) in self.region_rooms.items()}}

    def _restore(self, d: dict[str, Any]) -> bool:
        n = len(self.objects)
        try:
            score = np.array(d["room_score"], dtype=np.float64).reshape(n, len(ROOM_CUES))
            region = np.array(d["region"], dtype=np.int64).reshape(n)
            blocked = np.array(d["blocked"], dtype=np.int64).reshape(-1, 2)
            rooms = {int(k): (v[0], {str(r): float(x) for r, x in v[1].items()}) for k, v in d["region_rooms"].items()}
            open_plan = {int(k) for k in d.get("open_plan", [])}
            confidence = {int(k): float(v) for k, v in d.get("region_confidence", {}).items()}
            vis = np.ones((n, n), dtype=bool)
            vis[blocked[:, 0], blocked[:, 1]] = False
            vis[blocked[:, 1], blocked[:, 0]] = False
        except (KeyError, TypeError, ValueError, IndexError, AttributeError):
            return False  # not what _stored writes: computed again
        self.visible, self.room_score, self.region, self.region_rooms = vis, score, region, rooms
        self.open_plan, self.region_confidence = open_plan, confidence
        return True

    def _room_scores(self) -> NDArray[np.float64]:
        """(n, rooms) strongest cue per room type: max over cue objects of w * exp(-d^2 / 2 sigma^2),
        d the walking distance (geodesic through free space and furniture, not walls, when a grid
        is known). Cues of equal room and weight share one multi-source distance field."""
        n = len(self.objects)
        score = np.zeros((n, len(ROOM_CUES)))
        groups: dict[tuple[int, float], list[int]] = {}
        for k, lab in enumerate(self.labels):
            for r, cues in enumerate(ROOM_CUES.values()):
                if lab in cues:
                    groups.setdefault((r, cues[lab]), []).append(k)
        if not groups:
            return score
        sigma = self.config.room_sigma
        if self.occupancy is not None:
            from capnav.language.rooms import box_min, geodesic_from_boxes, walkable_domain

            spec = self.occupancy.spec
            domain = walkable_domain(self.occupancy, self.lo, self.hi)
            # The inner half of each box: a box's rim may poke through the wall it stands against.
            q = 0.25 * (self.hi - self.lo)
            ilo, ihi = self.lo + q, self.hi - q
        for (r, w), members in groups.items():
            if self.occupancy is not None:
                field = geodesic_from_boxes(domain, spec, ilo[members], ihi[members], limit_m=4 * sigma)
                d = np.array([box_min(field, spec, ilo[j], ihi[j]) for j in range(n)])
                d[members] = 0.0
            else:
                eu = np.linalg.norm(self.xy[:, None, :] - self.xy[None, members, :], axis=2)
                d = np.where(self.visible[:, members], eu, np.inf).min(axis=1)
            score[:, r] = np.maximum(score[:, r], w * np.exp(-0.5 * (d / sigma) ** 2))
        return score

    def _regions(self) -> None:
        """Rooms from the free space: each object belongs to the region it is reached from, and a
        region's type is the room type most probable given the categories standing in it
        (``room_prior.room_posterior``, kept in ``region_confidence``), when that reaches
        ``room_confidence``; else it has none. Its per-type scores stay the cues' noisy-or.
        A region whose cues name two types about equally (an open plan: a kitchen open to the
        living room) keeps the per-object distance-based scores."""
        from capnav.language.room_prior import best_room
        from capnav.language.rooms import object_region, room_regions

        assert self.occupancy is not None
        spec = self.occupancy.spec
        labels = room_regions(self.occupancy, self.lo, self.hi, self.config.door_width, self.config.min_room_m2)
        if labels.max() < 1:
            return  # one region or none: the walls say nothing about rooms
        self.region = np.array([object_region(labels, spec, lo, hi) for lo, hi in zip(self.lo, self.hi, strict=True)],
                               dtype=np.int64)
        for k in sorted({int(r) for r in self.region} - {-1}):
            members = np.flatnonzero(self.region == k)
            here = [self.labels[i] for i in members]
            strength, mass = {}, {}
            for room, cues in ROOM_CUES.items():
                w = [cues[lab] for lab in here if lab in cues]
                strength[room] = float(1.0 - np.prod([1.0 - x for x in w]))
                mass[room] = float(sum(w))
            ranked = sorted(mass.items(), key=lambda kv: -kv[1])
            # Two room types with about as much cue weight (a kitchen open to the living room):
            # an open plan, decided per object by its nearest cues. A desk in a bedroom is not one.
            if len(ranked) > 1 and ranked[1][1] >= self.config.open_plan_ratio * ranked[0][1] \
                    and strength[ranked[1][0]] >= self.config.region_strong and strength[ranked[0][0]] \
                    >= self.config.region_strong:
                self.region_rooms[k] = (None, strength)
                self.open_plan.add(k)
                continue
            # The type from the posterior; the per-type cue strengths stay what room constraints weigh
            # (a wardrobe beside the desk is still a bedroom cue there).
            sure, conf = best_room(here, self.config.room_confidence)
            self.region_rooms[k] = (sure if sure in ROOM_CUES else None, strength)
            self.region_confidence[k] = conf
        for i, reg in enumerate(self.region):
            typed = self.region_rooms.get(int(reg))
            if typed is not None and typed[0] is not None:
                self.room_score[i] = np.array([typed[1][r] for r in ROOM_CUES])

    # -- walls ---------------------------------------------------------------------------------
    def _wall_mask(self) -> NDArray[np.bool_] | None:
        if self.occupancy is None:
            return None
        from capnav.language.rooms import fill_gaps

        spec = self.occupancy.spec
        wall = fill_gaps(self.occupancy.cells) == OCCUPIED
        m = self.config.object_margin
        for lo, hi in zip(self.lo, self.hi, strict=True):
            r0, c0 = spec.to_cell(lo - m)
            r1, c1 = spec.to_cell(hi + m)
            wall[max(r0, 0):max(r1 + 1, 0), max(c0, 0):max(c1 + 1, 0)] = False
        return wall

    def _line_of_sight(self) -> NDArray[np.bool_]:
        n = len(self.objects)
        vis = np.ones((n, n), dtype=bool)
        wall = self._wall_mask()
        if wall is None or n < 2 or self.occupancy is None:
            return vis
        spec = self.occupancy.spec
        ii, jj = np.triu_indices(n, k=1)
        # Only near pairs matter ("next to"); farther pairs are left visible, unused.
        near = self.gap[ii, jj] <= self.config.los_range
        ii, jj = ii[near], jj[near]
        if len(ii) == 0:
            return vis
        steps = max(2, int(np.ceil(float(np.max(np.linalg.norm(self.xy[ii] - self.xy[jj], axis=1))) / spec.resolution)))
        t = np.linspace(0.0, 1.0, steps)[None, :, None]
        chunk = max(1, 2_000_000 // steps)  # bound the (pairs, steps, 2) temporary
        for s in range(0, len(ii), chunk):
            i, j = ii[s:s + chunk], jj[s:s + chunk]
            pts = self.xy[i][:, None, :] * (1 - t) + self.xy[j][:, None, :] * t
            rc = spec.to_cell(pts)
            inside = spec.inside(rc)
            rr = np.clip(rc[..., 0], 0, spec.rows - 1)
            cc = np.clip(rc[..., 1], 0, spec.cols - 1)
            blocked = (wall[rr, cc] & inside).sum(axis=1) >= self.config.wall_cells
            vis[i[blocked], j[blocked]] = False
            vis[j[blocked], i[blocked]] = False
        return vis

    # -- rooms ---------------------------------------------------------------------------------
    def room_scores(self, i: int) -> dict[str, float]:
        """Per room type, the strongest cue (the nearest stove says "kitchen"; ten armchairs do
        not add up)."""
        return {room: float(v) for room, v in zip(ROOM_CUES, self.room_score[i], strict=True)}

    def _room(self, i: int) -> str | None:
        reg = int(self.region[i])
        typed = self.region_rooms.get(reg)
        if typed is not None and typed[0] is not None:
            return typed[0]
        if typed is not None and reg not in self.open_plan:
            return None  # a region whose contents make no room type sure (a sink alone, a hallway)
        scores = self.room_scores(i)
        room, best = max(scores.items(), key=lambda kv: kv[1])
        return room if best >= self.config.room_min_score else None

    def room_of(self, obj: MapObject) -> str | None:
        return self.rooms[self.index[obj.id]]

    # -- neighbours and sizes ------------------------------------------------------------------
    def neighbours(self, obj: MapObject, max_gap: float | None = None) -> list[tuple[MapObject, float]]:
        """Other-category objects whose boxes lie within ``max_gap`` m, nearest first, visible only."""
        i = self.index[obj.id]
        lim = self.config.next_to_distance if max_gap is None else max_gap
        cand = [(k, float(self.gap[i, k])) for k in range(len(self.objects))
                if k != i and self.labels[k] != self.labels[i] and self.gap[i, k] <= lim and self.visible[i, k]]
        cand.sort(key=lambda kv: (kv[1], float(np.linalg.norm(self.xy[kv[0]] - self.xy[i]))))
        return [(self.objects[k], g) for k, g in cand]

    def same_label(self, obj: MapObject) -> list[MapObject]:
        lab = self.labels[self.index[obj.id]]
        return [o for o, lb in zip(self.objects, self.labels, strict=True) if lb == lab]

    def size_rank(self, obj: MapObject) -> tuple[int, int]:
        """(rank, count) of the object's volume among its category, rank 0 = largest."""
        peers = self.same_label(obj)
        vols = sorted((-self.volume[self.index[o.id]], o.id) for o in peers)
        order = [oid for _, oid in vols]
        return order.index(obj.id), len(peers)


def canonical_room(text: str) -> str | None:
    return ROOM_SYNONYMS.get(text.strip().lower())


__all__ = ["CACHE_KEY", "HALLWAY", "NAMES", "ROOM_CUES", "ROOM_SYNONYMS", "ContextConfig", "SceneContext",
           "canonical_label", "canonical_room", "label_of", "room_ending", "room_starting", "rooms_starting"]
