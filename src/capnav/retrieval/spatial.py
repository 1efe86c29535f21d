"""Geometry of the relations that need more than the gap between two boxes: "between" two
landmarks, "at the end of" a long one, and distances along the floor.

Why: "the lamp between the bed and the wardrobe" is the object on the line joining the two,
not the one nearest either; "the stool at the end of the counter" sits beyond a short edge of the
table, not along its long side. Both are measured on what the map observed: object centres and
the footprint (convex hull of the fused points in x, y). "The nearest plant to me" is the one the
robot walks to first, not the one nearest through a wall: :class:`FloorDistances` measures along
the map's floor (paper eq. 17's straight grid distance stays an option, ``RetrievalConfig.distance``).
"""

from __future__ import annotations

import threading

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.grid import OCCUPIED, OccupancyGrid
from capnav.language.rooms import box_cells, box_seeds, fill_gaps

#: Below this length / width ratio a footprint has no long axis, so no "end" (a round or square
#: table): "at the end of" is then read as "next to".
MIN_ELONGATION = 1.25
#: An object whose own cells no walk reaches is measured at the ring of cells around it (m).
RING = 0.3
#: Walks a ``FloorDistances`` keeps by default (per source cell; an entry holds one float per
#: object, not the field): at most this many sources and this many bytes. A robot that asks again
#: from where it stands, or the goal sequence after it, then pays no walk.
CACHE_SOURCES = 1024
CACHE_BYTES = 8 << 20
#: Bytes of walk fields (one per object, :func:`capnav.core.geodesic.walk_field`) a
#: ``FloorDistances`` keeps: 4 bytes a cell, 720 kB per object on a 24 x 18 m floor of 5 cm cells,
#: so a 300-object map's fields fit. 0: none.
FIELD_BYTES = 256 << 20
#: Walk fields made per ranking that needs them (the rest on later rankings, or ahead by
#: ``prepare``): a ranking of twenty chairs does not pay twenty whole walks at once.
FIELDS_PER_ASK = 2


def segment_distance(p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """Distance from point ``p`` to the segment ``a``-``b`` (to the nearer end beyond it)."""
    ab = b - a
    denom = float(ab @ ab)
    t = 0.0 if denom == 0.0 else float(np.clip((p - a) @ ab / denom, 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def oriented_box(footprint: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], float, float]:
    """(centre, unit long axis, half length, half width) of the footprint's minimum-area
    rectangle, searched over the directions of its hull edges (rotating calipers)."""
    pts = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
    if len(pts) < 3:
        c = pts.mean(axis=0) if len(pts) else np.zeros(2)
        return c, np.array([1.0, 0.0]), 0.0, 0.0
    edges = np.diff(np.vstack([pts, pts[:1]]), axis=0)
    angles = np.unique(np.round(np.arctan2(edges[:, 1], edges[:, 0]) % (np.pi / 2), 6))
    best: tuple[float, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]] | None = None
    for th in angles:
        u = np.array([np.cos(th), np.sin(th)])
        v = np.array([-u[1], u[0]])
        pu, pv = pts @ u, pts @ v
        area = float((pu.max() - pu.min()) * (pv.max() - pv.min()))
        if best is None or area < best[0] - 1e-12:
            lo = np.array([pu.min(), pv.min()])
            hi = np.array([pu.max(), pv.max()])
            best = (area, u, lo, hi)
    assert best is not None
    _, u, lo, hi = best
    v = np.array([-u[1], u[0]])
    mid = (lo + hi) / 2
    centre = mid[0] * u + mid[1] * v
    half = (hi - lo) / 2
    if half[1] > half[0]:
        return centre, v, float(half[1]), float(half[0])
    return centre, u, float(half[0]), float(half[1])


def has_long_axis(footprint: NDArray[np.float64]) -> bool:
    """Whether the footprint is elongated enough to have ends (``MIN_ELONGATION``)."""
    _, _, hl, hw = oriented_box(footprint)
    return hw > 0.0 and hl >= MIN_ELONGATION * hw


def end_distance(p: NDArray[np.float64], footprint: NDArray[np.float64]) -> float:
    """Distance from ``p`` to the nearer end of the footprint's long axis (the middle of a short
    edge of its minimum-area rectangle)."""
    centre, u, hl, _ = oriented_box(footprint)
    return float(min(np.linalg.norm(p - (centre + hl * u)), np.linalg.norm(p - (centre - hl * u))))


#: ``RetrievalConfig.distance`` values: along the floor, or eq. 17's straight line on the grid.
DISTANCES = ("walking", "straight")


class FloorDistances:
    """Walking distances (m) on a map's top-down grid from a point, or from landmark objects, to
    every object: one Dijkstra per source, shared by all candidates, through every cell not seen
    occupied and through the objects' own boxes (a sofa is walked around, but an object's cells
    are where it is reached), never through walls. Results are cached per source cell
    (``cache_size`` sources, default ``CACHE_SOURCES`` within ``CACHE_BYTES``; 0: none)."""

    def __init__(self, occ: OccupancyGrid, los: NDArray[np.float64], his: NDArray[np.float64],
                 cache_size: int | None = None, field_bytes: int | None = None) -> None:
        self.spec = occ.spec
        self.los = np.asarray(los, dtype=np.float64).reshape(-1, 2)
        self.his = np.asarray(his, dtype=np.float64).reshape(-1, 2)
        dom = fill_gaps(occ.cells) != OCCUPIED
        for lo, hi in zip(self.los, self.his, strict=True):
            (r0, c0), (r1, c1) = self.spec.to_cell(lo), self.spec.to_cell(hi)
            dom[max(r0, 0):max(r1 + 1, 0), max(c0, 0):max(c1 + 1, 0)] = True
        self.domain = dom
        # numba (0.5 s of CPU to import) only when a walking distance is asked for, not per query.
        from capnav.core.geodesic import walk_base

        self._base = walk_base(dom)  # the padded start of every search, copied per source
        # Each object's cells and its cells grown by RING, once per map (read by every search).
        self._boxes = np.array([box_cells(self.spec, lo, hi) for lo, hi in zip(self.los, self.his, strict=True)],
                               dtype=np.int64).reshape(-1, 4)
        self._grown = np.array([box_cells(self.spec, lo - RING, hi + RING)
                                for lo, hi in zip(self.los, self.his, strict=True)], dtype=np.int64).reshape(-1, 4)
        if cache_size is None:  # an entry is one float per object: keep CACHE_BYTES of them
            cache_size = int(min(CACHE_SOURCES, max(8, CACHE_BYTES // (8 * max(len(self._boxes), 1)))))
        if cache_size < 0:
            raise InputError(f"FloorDistances cache_size must be >= 0 (0: no cache), got {cache_size}")
        self._cache: dict[tuple[int, ...], NDArray[np.float64]] = {}
        self._size = cache_size
        # Walk fields: per object, the exact walk from its cells to every cell (walks are
        # symmetric), so a ranking from a robot no walk started from is a lookup per object.
        self._fields: dict[int, NDArray[np.uint32] | None] = {}
        self._field_bytes = FIELD_BYTES if field_bytes is None else int(field_bytes)
        self._ranked: dict[int, int] = {}  # rankings each object was asked in without a field
        self._held = 0  # bytes of the kept fields
        self._lock = threading.Lock()

    # -- walk fields -------------------------------------------------------------------------
    def field(self, i: int, make: bool = True) -> NDArray[np.uint32] | None:
        """Object ``i``'s walk field (made now unless ``make`` is False; None when it has none:
        no cell, a walk too long for its counts, or no room in ``field_bytes``)."""
        with self._lock:
            if i in self._fields:
                hit = self._fields.pop(i)
                self._fields[i] = hit  # the most recently used
                return hit
        if not make or self._field_bytes <= 0:
            return None
        from capnav.core.geodesic import walk_field

        r0, c0, r1, c1 = (int(v) for v in self._boxes[i])
        made: NDArray[np.uint32] | None = None
        if r1 >= r0 and c1 >= c0:
            rr, cc = np.mgrid[r0:r1 + 1, c0:c1 + 1]
            f = walk_field(self._base, self.spec.cols, np.stack([rr.ravel(), cc.ravel()], axis=1).astype(np.int64))
            made = f if len(f) else None
        size = 0 if made is None else made.nbytes
        with self._lock:  # a server makes fields on a thread of its own while asks read them
            if i in self._fields:
                return self._fields[i]
            while self._fields and self._held + size > self._field_bytes:
                gone = self._fields.pop(next(iter(self._fields)))  # the least recently used
                self._held -= 0 if gone is None else gone.nbytes
            if size <= self._field_bytes:
                self._fields[i] = made
                self._held += size
        return made

    def _looked_up(self, rc: tuple[int, int], among: NDArray[np.intp]) -> NDArray[np.float64] | None:
        """``walk_box_minima_of`` from the cell ``rc`` for ``among`` read off their walk fields: the
        same floats (exact walks, :func:`capnav.core.geodesic.walk_value`), or None when an
        object has no field yet (at most ``FIELDS_PER_ASK`` are made, for objects ranked before)
        or the walk would not stop at them (one is never reached)."""
        from capnav.core.geodesic import NO_WALK, walk_value

        if self._field_bytes <= 0 or not self.domain[rc]:
            return None
        fields = [self.field(int(i), make=False) for i in among]
        made = 0
        for k, i in enumerate(among):
            if fields[k] is None and int(i) not in self._fields:
                n = self._ranked[int(i)] = self._ranked.get(int(i), 0) + 1
                if n >= 2 and made < FIELDS_PER_ASK:
                    fields[k] = self.field(int(i))
                    made += 1
        if any(f is None for f in fields):
            if len(self._ranked) > 8 * len(self._boxes) + 64:
                self._ranked.clear()
            return None
        at = rc[0] * self.spec.cols + rc[1]
        out = np.full(len(self._boxes), np.nan)
        for k, i in enumerate(among):
            v = int(fields[k][at])  # type: ignore[index]
            if v == int(NO_WALK):
                return None  # the walk would run on to the end and measure every object
            out[i] = walk_value(v) * self.spec.resolution
        return out

    @property
    def held(self) -> int:
        """Bytes of the walk fields kept."""
        return self._held

    def prepare(self) -> int:
        """Make every object's walk field (a server does it at load, off its asks); how many
        objects have one."""
        return sum(self.field(i) is not None for i in range(len(self._boxes)))

    def _per_object(self, key: tuple[int, ...], los: NDArray[np.float64], his: NDArray[np.float64],
                    among: NDArray[np.intp] | None = None) -> NDArray[np.float64]:
        """The walk's minimum per object (nan where not measured: only ``among`` was asked for)."""
        hit = self._cache.pop(key, None)
        missing = None if hit is None else np.isnan(hit if among is None else hit[among])
        if hit is None or (missing is not None and missing.any()):
            seeds = box_seeds(self.domain, self.spec, los, his)
            ask = None if among is None else np.asarray(among if hit is None else among[missing], dtype=np.int64)
            looked = None
            if key[0] == "point" and ask is not None and len(ask) and len(seeds) == 1:
                looked = self._looked_up((int(seeds[0, 0]), int(seeds[0, 1])), ask)
            if looked is not None:
                new = looked
            elif len(seeds) == 0:
                new = np.full(len(self._boxes), np.inf)
            elif among is None:
                from capnav.core.geodesic import walk_box_minima

                new = walk_box_minima(self._base, self.spec.cols, seeds, self._boxes, self._grown,
                                      self.spec.resolution, RING)
            else:
                from capnav.core.geodesic import walk_box_minima_of

                assert ask is not None
                new = walk_box_minima_of(self._base, self.spec.cols, seeds, self._boxes, self._grown,
                                         self.spec.resolution, RING, ask)
            if hit is not None:  # what an earlier, partial walk from here measured stays
                new = np.where(np.isnan(new), hit, new)
            hit = new
            while self._cache and len(self._cache) >= self._size:
                self._cache.pop(next(iter(self._cache)))  # the least recently used source
        if self._size > 0:
            self._cache[key] = hit
        return hit

    def from_point(self, xy: tuple[float, float], among: NDArray[np.intp] | None = None) -> NDArray[np.float64]:
        """Metres along the floor from ``xy`` to each object (inf when no walk reaches it). With
        ``among`` (object indices) the walk may stop once those are measured: the others are then
        nan, unless no walk reaches one of ``among`` (then the walk covered the floor and every
        object has its value)."""
        p = np.asarray(xy, dtype=np.float64).reshape(1, 2)
        rc = self.spec.to_cell(p[0])
        idx = None if among is None else np.unique(np.asarray(among, dtype=np.intp))
        return self._per_object(("point", int(rc[0]), int(rc[1])), p, p, idx)  # type: ignore[arg-type]

    def from_objects(self, idx: NDArray[np.intp]) -> NDArray[np.float64]:
        """Metres along the floor from the nearest of the objects ``idx`` to each object."""
        ids = tuple(int(i) for i in np.asarray(idx).ravel())
        return self._per_object(("objects", *ids), self.los[list(ids)], self.his[list(ids)])  # type: ignore[arg-type]


__all__ = ["DISTANCES", "MIN_ELONGATION", "FloorDistances", "end_distance", "has_long_axis", "oriented_box",
           "segment_distance"]
