"""A route into a room ("the first armchair you reach coming into the lounge from the kitchen", "the
plant on your left as you walk from the hall into the bedroom", "the third lamp from the
door to the landing"): candidates ordered by how far they stand from the way in, and split by the
side they are on as seen walking through it.

The way in is found in the map, never in the simulator's doors: the free space is cut into room
regions (``capnav.language.rooms.segment_rooms``, the regions rooms are typed on) and the way in
from room type A to the candidate's region is where that region touches a region typed A. The
walking direction is from A's side of that boundary to the candidate's side; "left" is to the
left of it (x east, y north). A candidate whose region touches no region of type A is ordered
last, and said so."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from capnav.language.context import HALLWAY
from capnav.retrieval.constraints.base import SUPPORTED, UNOBSERVED, Evidence, RankingConstraint, RankState, ranking
from capnav.retrieval.query import ParsedQuery

if TYPE_CHECKING:
    from capnav.language.context import SceneContext

_CACHE = "route/regions"


def region_labels(scene: SceneContext) -> NDArray[np.int32] | None:
    """The room region of every grid cell (-1 outside the walkable space), as the scene types them."""
    from capnav.language.rooms import room_regions

    if scene.occupancy is None:
        return None
    return room_regions(scene.occupancy, scene.lo, scene.hi, scene.config.door_width, scene.config.min_room_m2)


def way_in(labels: NDArray[np.int32], to_region: int, from_regions: set[int]
           ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """(door cell, walking direction) in cell coordinates (row, col) of the boundary where
    ``to_region`` touches any of ``from_regions``, or None when they do not touch."""
    inside = labels == to_region
    outside = np.isin(labels, list(from_regions))
    a_cells, b_cells = [], []
    for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        shifted = np.zeros_like(outside)
        src = outside[max(dr, 0):outside.shape[0] + min(dr, 0), max(dc, 0):outside.shape[1] + min(dc, 0)]
        shifted[max(-dr, 0):outside.shape[0] + min(-dr, 0), max(-dc, 0):outside.shape[1] + min(-dc, 0)] = src
        edge = inside & shifted
        rr, cc = np.nonzero(edge)
        b_cells.append(np.stack([rr, cc], axis=1))
        a_cells.append(np.stack([rr + dr, cc + dc], axis=1))
    b = np.concatenate(b_cells).astype(np.float64)
    if not len(b):
        return None
    a = np.concatenate(a_cells).astype(np.float64)
    door = b.mean(axis=0)
    d = b.mean(axis=0) - a.mean(axis=0)
    if np.linalg.norm(d) < 1e-9:  # a symmetric boundary: into the region's middle
        rr, cc = np.nonzero(inside)
        d = np.array([rr.mean(), cc.mean()]) - door
    return door, d / max(float(np.linalg.norm(d)), 1e-9)


def neighbours(labels: NDArray[np.int32], region: int) -> set[int]:
    """The regions that touch ``region`` (its doors lead to them)."""
    inside = labels == region
    out: set[int] = set()
    for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        a = inside[max(dr, 0):inside.shape[0] + min(dr, 0), max(dc, 0):inside.shape[1] + min(dc, 0)]
        b = labels[max(-dr, 0):labels.shape[0] + min(-dr, 0), max(-dc, 0):labels.shape[1] + min(-dc, 0)]
        out |= {int(x) for x in np.unique(b[a])}
    return out - {region, -1}


def side_of(heading: NDArray[np.float64], door: NDArray[np.float64], lo: NDArray[np.float64],
            hi: NDArray[np.float64]) -> float:
    """+1 when the box ``lo``..``hi`` lies wholly left of the line walked from ``door`` along
    ``heading``, -1 wholly right, 0 when the line crosses it (the thing is straight ahead: a
    cabinet on the far wall is on neither side of someone walking towards it)."""
    corners = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [lo[0], hi[1]], [hi[0], hi[1]]]) - door
    cross = heading[0] * corners[:, 1] - heading[1] * corners[:, 0]
    return 1.0 if (cross > 0).all() else -1.0 if (cross < 0).all() else 0.0


@ranking
class Route(RankingConstraint):
    kind = "route"
    order = 40  # after the room has narrowed the candidates, before the sort

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return q.origin_room is not None

    def rank(self, st: RankState) -> None:
        q, r, pool = st.q, st.r, st.pool
        scene = r.scene
        if not r.config.use_predicates or not len(pool):
            return
        cache = r.__dict__.setdefault("_route_cache", {})
        if _CACHE not in cache:
            cache[_CACHE] = region_labels(scene)
        labels = cache[_CACHE]
        # A hallway has no objects of its own to type it by: the regions no room type was inferred for.
        typed = None if q.origin_room == HALLWAY else q.origin_room
        origin = {k for k, (room, _) in scene.region_rooms.items() if room == typed}
        if labels is None or not origin:
            st.notes.append(f"no region of the map is typed {q.origin_room}, so the way in from it is not known; "
                            "the route was not used")
            return
        spec = scene.occupancy.spec if scene.occupancy is not None else None
        assert spec is not None
        # "the second bookshelf from the office door" when the bookshelves stand in the office:
        # the door named by the candidates' own room is that room's door, the way in from the
        # regions next to it (the nearest of them when it has several).
        own = all(int(scene.region[i]) in origin for i in pool if int(scene.region[i]) >= 0)
        dist = np.full(len(pool), np.inf)
        ahead = np.zeros(len(pool))  # how far along the walking direction (m)
        side = np.zeros(len(pool))  # +1 left, -1 right, 0 across the line walked (straight ahead)
        doors: dict[int, list[tuple[NDArray[np.float64], NDArray[np.float64]]]] = {}
        for k, i in enumerate(pool):
            reg = int(scene.region[i])
            if reg < 0 or (reg in origin and not own):
                continue
            if reg not in doors:
                ways = [way_in(labels, reg, {n}) for n in sorted(neighbours(labels, reg))] if own \
                    else [way_in(labels, reg, origin)]
                doors[reg] = [w for w in ways if w is not None]
            for door_rc, d_rc in doors[reg]:
                door = spec.to_world(np.round(door_rc).astype(np.int64)[None])[0]
                tip = spec.to_world(np.round(door_rc + 10 * d_rc).astype(np.int64)[None])[0]
                heading = (tip - door) / max(float(np.linalg.norm(tip - door)), 1e-9)
                v = np.asarray(r.objects[i].position[:2], dtype=np.float64) - door
                if float(np.linalg.norm(v)) < dist[k]:
                    dist[k] = float(np.linalg.norm(v))
                    ahead[k] = float(heading @ v)
                    side[k] = side_of(heading, door, scene.lo[i], scene.hi[i])
        known = np.isfinite(dist)
        if not known.any():
            st.notes.append(f"no candidate stands in a region that opens onto the {q.origin_room}; "
                            "the route was not used")
            return
        want = {"left": 1.0, "right": -1.0}.get(q.side or "", 0.0)
        for k, i in enumerate(pool):
            if not known[k]:
                st.report(self.kind, int(i), Evidence(self.kind, UNOBSERVED, 0.0,
                                                      f"its room does not open onto the {q.origin_room}"))
                continue
            where = f"{dist[k]:.1f} m from the {q.origin_room}'s door" if own else \
                f"{dist[k]:.1f} m from the way in from the {q.origin_room}"
            if want:
                where += f", on the {'left' if side[k] > 0 else 'right'}" if side[k] else ", straight ahead"
            st.report(self.kind, int(i), Evidence(self.kind, SUPPORTED, 1.0, where))
        # "the bookshelf furthest from the office door": the order from the way in, reversed. Along
        # one side ("the third thing on your left"), the order they are passed: how far ahead.
        met = ahead if want else dist
        rank_key = np.where(known, -met if q.proximity == "farthest" else met, 1e9)
        if want:
            # The side first, then the order met from the way in.
            st.group_keys.append(-(side == want).astype(np.float64))
        st.group_keys.append(rank_key)
        st.values["from the way in (m)"] = np.where(known, dist, -1.0)
        st.predicate, st.mode = "route", "predicate"
        st.notes.append((f"ordered from the door of the {q.origin_room} they stand in" if own
                         else f"ordered from the way in from the {q.origin_room}")
                        + (f", {q.side} side first" if want else ""))
