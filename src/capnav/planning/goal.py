"""Goal selection (Sec. 3.4): where a person sent to the object would stop.

The paper turns the object's cell into a waypoint; an object's own cell is an obstacle, so a
goal is a free cell within the reach radius of the footprint, aiming ``goal_margin`` inside it,
facing the object. Within 1 m of an object may lie behind its wall, in the next room or on
floor nobody saw, so among those cells the goal rule (``PlannerConfig.prefer_line_of_sight``)
asks for one that

- stands on seen free floor (a FREE cell of the map, never an UNKNOWN one),
- lies in the free-space region (room, :func:`capnav.language.rooms.segment_rooms`) the object is
  reached from, which puts it on the object's open side rather than behind the wall it stands on,
- sees the object from the robot's eye height through the mapped voxels
  (:mod:`capnav.planning.sight`: the TV on the wall is seen over the cabinet under it),

and takes the cheapest such cell by path cost from the robot. The search settles candidates in
cost order and stops at the first that passes (:class:`capnav.planning.nearest.NearestSearch`), so
a goal costs the cells cheaper than it, not a whole-grid search. When no cell passes, the rule is
relaxed one condition at a time and the reason says which one failed.

Which cells pass the whole rule does not depend on where the robot stands, so an object asked
for again (or every object, ``prepare_goal``: a server does it at load) keeps a goal field: those
cells and a lower bound of the path cost to them from every cell (``GoalField``). The search from
a robot no search started from then heads straight for the cheapest of them, the same cell (or
one of equal cost) at the same cost, expanding the cells near its cheapest path (about 1,800 at
the median on the 300-object benchmark map) instead of every cell cheaper than the goal in every
direction (about 13,000).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.grid import FREE, OCCUPIED, OccupancyGrid
from capnav.planning.config import PlannerConfig
from capnav.planning.costmap import Costmap, build_costmap, locate_start
from capnav.planning.nearest import NO_PATH, NearestSearch, goal_field, padded_weights
from capnav.planning.polygon import polygon_distance
from capnav.planning.sight import HeightColumns, SightTest


@dataclass(frozen=True)
class GoalPose:
    """Where to stop: ``xy`` world, ``yaw`` facing the object, its grid ``cell``; whether it lies
    within ``reach`` of the footprint, why it was chosen, and its distance / path cost (m).
    ``in_sight`` / ``in_room``: whether the cell sees the object and lies in the object's room
    (None when not asked: the paper's rule, or no room found around the object)."""

    xy: NDArray[np.float64]
    yaw: float
    cell: tuple[int, int]
    reached_within_reach: bool
    reason: str
    distance_to_object: float
    path_cost: float
    in_sight: bool | None = None
    in_room: bool | None = None
    on_seen_floor: bool = True  # False: the only cells within reach are unknown space

    def to_dict(self) -> dict[str, Any]:
        return {"xy": [round(float(v), 4) for v in self.xy], "yaw": round(self.yaw, 4), "cell": list(self.cell),
                "reached_within_reach": self.reached_within_reach, "reason": self.reason,
                "distance_to_object": round(self.distance_to_object, 4), "path_cost": round(self.path_cost, 4),
                "in_sight": self.in_sight, "in_room": self.in_room, "on_seen_floor": self.on_seen_floor}


def check_footprint(footprint: object) -> NDArray[np.float64]:
    fp = np.asarray(footprint, dtype=np.float64)
    if fp.ndim != 2 or fp.shape[1] != 2 or len(fp) == 0:
        raise InputError(f"target footprint must be a (K, 2) array of world x, y, got shape {fp.shape}")
    if not np.isfinite(fp).all():
        raise InputError("target footprint has non-finite coordinates")
    return fp


def room_labels(cm: Costmap) -> NDArray[np.int32]:
    """Free-space regions of the costmap's grid (one label per room, -1 on walls), computed once per
    costmap: the walkable domain is every cell not seen occupied (furniture is occupied, but a room
    is one region around it once doorways are cut by the erosion). A region mostly of unknown
    space is no room (the band nobody saw beyond the outer walls): -1 too, so an object in a
    corner is not given to the outside."""
    labels = cm.cache.get("rooms")
    if labels is None:
        from capnav.language.rooms import fill_gaps, segment_rooms

        cells = fill_gaps(cm.occ.cells)
        labels = segment_rooms(cells != OCCUPIED, cm.spec)
        inside = labels >= 0
        if inside.any():
            k = labels[inside]
            seen = np.bincount(k, weights=(cells[inside] == FREE).astype(np.float64))
            unseen = seen < 0.5 * np.bincount(k)
            labels = np.where(inside & unseen[np.maximum(labels, 0)], -1, labels).astype(np.int32)
        cm.cache["rooms"] = labels
    return np.asarray(labels)


#: Objects whose goal setup (``_Around``, tens of kB each) a costmap keeps: the most recently asked.
AROUND_CACHE = 256


@dataclass(frozen=True)
class _Around:
    """What goal selection needs of one object on one costmap, wherever the robot stands: the
    window of cells that can be within reach (``lo``..``hi``), their distances to the footprint,
    which stand on seen free floor where goals may be, which lie in the object's room, and the
    sight test. The weights are read per search (``mark_blocked`` raises them in place)."""

    lo: NDArray[np.intp]
    hi: NDArray[np.intp]
    dist: NDArray[np.float64]
    seen: NDArray[np.bool_]  # FREE on the map, and allowed
    in_room: NDArray[np.bool_]
    region: int
    sight: SightTest | None

    @property
    def win(self) -> tuple[slice, slice]:
        return slice(int(self.lo[0]), int(self.hi[0]) + 1), slice(int(self.lo[1]), int(self.hi[1]) + 1)

    @property
    def shape(self) -> tuple[int, int]:
        return int(self.hi[0] - self.lo[0] + 1), int(self.hi[1] - self.lo[1] + 1)

    def cells(self) -> NDArray[np.intp]:
        """The window's cells (N, 2) row, col, in the order of ``dist``."""
        rr, cc = np.mgrid[self.lo[0]:self.hi[0] + 1, self.lo[1]:self.hi[1] + 1]
        return np.stack([rr.ravel(), cc.ravel()], axis=1)


def _around(cm: Costmap, fp: NDArray[np.float64], cfg: PlannerConfig, cols: HeightColumns | None,
            z_range: tuple[float, float] | None, may: NDArray[np.bool_] | None) -> _Around:
    spec = cm.spec
    # Only cells in the footprint's box grown by the reach can be within reach: measure those.
    lo = np.clip(spec.to_cell(fp.min(axis=0) - cfg.reach), 0, [spec.rows - 1, spec.cols - 1])
    hi = np.clip(spec.to_cell(fp.max(axis=0) + cfg.reach), 0, [spec.rows - 1, spec.cols - 1])
    rr, cc = np.mgrid[lo[0]:hi[0] + 1, lo[1]:hi[1] + 1]
    rc = np.stack([rr.ravel(), cc.ravel()], axis=1)
    centres = spec.to_world(rc)
    dist = _distances(centres, fp)
    win = (slice(lo[0], hi[0] + 1), slice(lo[1], hi[1] + 1))
    seen = cm.occ.cells[win].ravel() == FREE
    if may is not None:
        seen &= may[win].ravel()
    person = cfg.prefer_line_of_sight
    region = -1
    in_room = np.ones(len(rc), dtype=bool)
    # The room matters only when a cell can be within reach (weights are only ever raised).
    if person and (seen & np.isfinite(cm.weights[win].ravel()) & (dist <= cfg.reach)).any():
        labels = room_labels(cm)
        from capnav.language.rooms import object_region

        region = object_region(labels, spec, fp.min(axis=0), fp.max(axis=0))
        if region >= 0:
            in_room = _inside_region(labels[win], region,
                                     cfg.robot_radius / spec.resolution).ravel()
    sight = SightTest(cm.occ, fp, polygon_centroid(fp), lo, hi, cols, z_range, cfg.eye_height) if person else None
    return _Around(lo, hi, dist, seen, in_room, region, sight)


def _around_key(fp: NDArray[np.float64], cfg: PlannerConfig, z_range: tuple[float, float] | None) -> Any:
    return (fp.shape, fp.tobytes(), cfg, None if z_range is None else (float(z_range[0]), float(z_range[1])))


def _around_cached(cm: Costmap, fp: NDArray[np.float64], cfg: PlannerConfig, cols: HeightColumns | None,
                   z_range: tuple[float, float] | None) -> _Around:
    """``_around`` kept per costmap for the most recently asked objects: a fleet asks for the same
    objects again and again, from wherever its robots stand."""
    kept: dict[Any, _Around] = cm.cache.setdefault("goal_around", {})
    key = _around_key(fp, cfg, z_range)
    hit = kept.pop(key, None)
    if hit is None:
        hit = _around(cm, fp, cfg, cols, z_range, None)
        while len(kept) >= AROUND_CACHE:
            kept.pop(next(iter(kept)), None)  # the least recently asked
    kept[key] = hit
    return hit


_FIELD_LOCK = threading.Lock()
#: Bytes of goal fields a costmap keeps (the most recently used objects'): 360 kB per object on a
#: 24 x 18 m floor of 5 cm cells, so a 300-object map's fields all fit.
FIELD_BYTES = 192 << 20


@dataclass(frozen=True)
class GoalField:
    """What makes an object's goal pose a short search from any start: the cells of its window
    that pass the whole goal rule (``accepted``, the window's shape; the rule does not depend on
    where the robot stands) and a lower bound of every cell's path cost to the nearest of them
    (``hq``, uint16 flat, :func:`capnav.planning.nearest.goal_field`). Made once per object and
    costmap; a contact mark (``mark_blocked``) drops them with the rest of the goal cache."""

    accepted: NDArray[np.bool_]
    hq: NDArray[np.uint16]

    @property
    def nbytes(self) -> int:
        return int(self.accepted.nbytes + self.hq.nbytes)


def _make_field(cm: Costmap, ar: _Around, cfg: PlannerConfig) -> GoalField | None:
    """The object's goal field, or None when no cell passes the whole rule (the search then runs
    on to the relaxed tiers, as without a field)."""
    free = ar.seen & np.isfinite(cm.weights[ar.win].ravel())
    target = free & (ar.dist <= cfg.reach - cfg.goal_margin) & ar.in_room
    idx = np.flatnonzero(target)
    if not len(idx):
        return None
    rc = ar.cells()[idx]
    if ar.sight is not None:
        ok = np.asarray(ar.sight(rc), dtype=bool)
        idx, rc = idx[ok], rc[ok]
        if not len(idx):
            return None
    accepted = np.zeros(len(ar.dist), dtype=bool)
    accepted[idx] = True
    base = cm.cache.get("goal_walk_base")
    if base is None:
        base = cm.cache["goal_walk_base"] = padded_weights(cm.weights)
    if "min_weight" not in cm.cache:
        finite = cm.weights[np.isfinite(cm.weights)]
        cm.cache["min_weight"] = float(finite.min()) if finite.size else 1.0
    return GoalField(accepted.reshape(ar.shape), goal_field(cm.weights, rc, cm.cache["min_weight"], base))


def _field_for(cm: Costmap, key: Any, ar: _Around, cfg: PlannerConfig, make: bool = False) -> GoalField | None:
    """The kept goal field of the object ``key``; made on the object's second search from a
    start no pose is kept for (a one-shot query does not pay for a field it uses once), or at
    once with ``make`` (``prepare_goal``)."""
    with _FIELD_LOCK:  # a server makes fields on a thread of its own while asks read them
        kept: dict[Any, GoalField | None] = cm.cache.setdefault("goal_field", {})
        if key in kept:
            hit = kept.pop(key)
            kept[key] = hit  # the most recently used
            return hit
        seen: dict[Any, int] = cm.cache.setdefault("goal_field_asked", {})
        if not make:
            seen[key] = seen.get(key, 0) + 1
            if seen[key] < 2:
                if len(seen) > 4 * AROUND_CACHE:
                    seen.clear()
                return None
    made = _make_field(cm, ar, cfg)
    size = 0 if made is None else made.nbytes
    with _FIELD_LOCK:
        kept = cm.cache.setdefault("goal_field", {})
        cm.cache.setdefault("goal_field_asked", {}).pop(key, None)
        if key in kept:
            return kept[key]
        held = sum(0 if f is None else f.nbytes for f in kept.values())
        while kept and held + size > FIELD_BYTES:
            gone = kept.pop(next(iter(kept)))  # the least recently used
            held -= 0 if gone is None else gone.nbytes
        if size <= FIELD_BYTES:
            kept[key] = made
    return made


def prepare_goal(occ: OccupancyGrid, target_footprint: NDArray[np.floating], costmap: Costmap,
                 config: PlannerConfig | None = None, *, z_range: tuple[float, float] | None = None) -> bool:
    """Make the goal field of an object ahead of its asks (a server does it for every object at
    load); whether the object has one (False: no cell passes the whole rule, or no room in
    ``FIELD_BYTES``)."""
    cfg = config or PlannerConfig()
    fp = check_footprint(target_footprint)
    key = _around_key(fp, cfg, z_range)
    have = costmap.cache.get("goal_field", {})
    if key in have:
        return have.get(key) is not None
    # Not the kept setup: a server prepares on a thread of its own while its asks use that one.
    ar = _around(costmap, fp, cfg, costmap.columns, z_range, None)
    return _field_for(costmap, key, ar, cfg, make=True) is not None and key in costmap.cache["goal_field"]


#: Goal poses a costmap keeps per (object, start cell): the most recently chosen. A robot that
#: asks again from where it stands (a second question, a retry, the plan after the answer), or a
#: fleet's robots parked at the same dock, get the pose without a search; about 1 kB each.
POSE_CACHE = 4096


def select_goal(occ: OccupancyGrid, target_footprint: NDArray[np.floating], start_xy: Any,
                config: PlannerConfig | None = None, costmap: Costmap | None = None, *,
                z_range: tuple[float, float] | None = None, columns: HeightColumns | None = None,
                allowed: NDArray[np.bool_] | None = None) -> GoalPose:
    """The cheapest cell (path cost from ``start_xy``) within ``reach - goal_margin`` of the
    footprint that meets the goal rule (module notes); else, relaxing one condition at a time, the
    cells within ``reach``, in sight from the next room, in the room but out of sight, any seen free
    cell within reach; else the reachable free cell closest to the object. The reason says which.

    ``z_range`` (m above the floor) is the object's height; ``columns`` (default: the costmap's)
    the map's observed heights for 3D sight. Without them every occupied cell blocks sight.
    ``allowed`` (the grid's shape) limits which cells may be goals, not which may be driven
    through: where the true robot fits on a relaxed costmap, and not where it failed to get.
    When no seen free cell is reachable the goal is the start cell, with the reason.
    """
    cfg = config or PlannerConfig()
    fp = check_footprint(target_footprint)
    cm = costmap if costmap is not None else build_costmap(occ, cfg, columns)
    cols = columns if columns is not None else cm.columns
    s_cell, _ = locate_start(cm, start_xy, cfg)
    if allowed is not None and np.shape(allowed) != cm.weights.shape:
        raise InputError(f"allowed goal cells must have the grid's shape {cm.weights.shape}, got {np.shape(allowed)}")
    if allowed is not None or cols is not cm.columns:
        may = np.ones(cm.weights.shape, dtype=bool) if allowed is None else np.asarray(allowed, dtype=bool)
        return _select(cm, fp, s_cell, cfg, _around(cm, fp, cfg, cols, z_range, may), may)
    # The pose depends on the object, the start cell and the weights only: kept per costmap
    # (dropped with the setup when a contact marks it, ``mark_blocked``).
    kept: dict[Any, GoalPose] = cm.cache.setdefault("goal_pose", {})
    key = (_around_key(fp, cfg, z_range), s_cell)
    hit = kept.pop(key, None)
    if hit is None:
        ar = _around_cached(cm, fp, cfg, cols, z_range)
        gfield = None if cm.cache.get("no_fields") else _field_for(cm, key[0], ar, cfg)
        hit = _select(cm, fp, s_cell, cfg, ar, None, gfield)
        while len(kept) >= POSE_CACHE:
            kept.pop(next(iter(kept)), None)  # the least recently chosen
    kept[key] = hit
    return replace(hit, xy=hit.xy.copy())


def _select(cm: Costmap, fp: NDArray[np.float64], s_cell: tuple[int, int], cfg: PlannerConfig, ar: _Around,
            allowed: NDArray[np.bool_] | None, gfield: GoalField | None = None) -> GoalPose:
    """``select_goal`` from the start cell ``s_cell`` with the object's setup ``ar`` (``allowed``:
    None when every cell may be a goal; ``gfield``: the object's goal field, when it has one)."""
    spec = cm.spec
    may = np.ones(cm.weights.shape, dtype=bool) if allowed is None else allowed
    lo, hi, dist, win = ar.lo, ar.hi, ar.dist, ar.win
    free = ar.seen & np.isfinite(cm.weights[win].ravel())
    within = free & (dist <= cfg.reach)
    near = within & (dist <= cfg.reach - cfg.goal_margin)
    person = cfg.prefer_line_of_sight
    region, in_room, sight = ar.region, ar.in_room, ar.sight
    room_flag = None if region < 0 or not person else True

    target = (near & in_room).reshape(ar.shape)
    if "min_weight" not in cm.cache:
        finite = cm.weights[np.isfinite(cm.weights)]
        cm.cache["min_weight"] = float(finite.min()) if finite.size else 1.0
    box = (int(lo[0]), int(lo[1]), int(hi[0]), int(hi[1]))
    hit: tuple[tuple[int, int], float] | None = None
    if gfield is not None and gfield.hq[s_cell[0] * cm.spec.cols + s_cell[1]] != NO_PATH:
        # The cells that pass the whole rule are known, and a lower bound of the cost to them from
        # every cell: the search goes to the cheapest of them, which is the first it settles.
        hit = NearestSearch(cm.weights, s_cell, gfield.accepted, box, cm.cache["min_weight"], gfield.hq).next()
    passed = hit is not None  # (else no cell passing the rule is reachable: on to the relaxed tiers)
    search = NearestSearch(cm.weights, s_cell, target, box, cm.cache["min_weight"])
    while hit is not None or (hit := search.next()) is not None:
        cell, g = hit
        hit = None
        if passed or sight is None or bool(sight(np.array([cell]))[0]):
            i = int((cell[0] - lo[0]) * (hi[1] - lo[1] + 1) + cell[1] - lo[1])
            why = f"the nearest reachable free cell {dist[i]:.2f} m from the object"
            if person:
                why += (", in the object's room" if region >= 0 else "") + ", in sight of it on the map"
            at = np.array(cell, dtype=np.intp)
            return _pose(at, spec.to_world(at), fp, True, why, float(dist[i]), g * spec.resolution,
                         None if sight is None else True, room_flag)
    # Nothing passes the whole rule: the costs of every reachable cell, then relax one condition at a time.
    field = search.finish()
    rc = ar.cells()
    centres = spec.to_world(rc)
    cost = field[win].ravel() * spec.resolution
    reach_ok = np.isfinite(cost)
    cut_off = int((within & ~reach_ok).sum())  # free floor within reach that no path gets to
    within &= reach_ok
    near &= reach_ok
    seen = np.zeros(len(rc), dtype=bool)
    if sight is not None and within.any():
        seen[within] = sight(rc[within])
    short = f"none within {cfg.reach - cfg.goal_margin:.2f} m"
    tiers: list[tuple[NDArray[np.bool_], str, bool | None, bool | None]] = []
    if person:
        where = ", in the object's room" if region >= 0 else ""
        tiers += [(within & in_room & seen, f"{where}, in sight of it on the map", True, room_flag)]
        if region >= 0:
            tiers.append((within & seen, ", in sight of it from outside its room (no cell of its room within "
                                         "reach sees it or is reachable)", True, False))
            tiers.append((within & in_room, ", in the object's room but out of sight (no reachable cell within "
                                            "reach sees it on the map)", False, True))
        tiers.append((within, ", neither in its room nor in sight of it (no reachable cell within reach is)",
                      False, False if region >= 0 else None))
    else:
        tiers.append((within, "", None, None))
    for ok, why, in_sight, room in tiers:
        if ok.any():
            k = ok & near
            i = _pick(np.nonzero(k if k.any() else ok)[0], cost, dist, not k.any(), spec.resolution)
            what = ("the nearest reachable free cell" if k.any() else
                    f"the nearest reachable free cell within reach ({short})")
            return _pose(rc[i], centres[i], fp, True, f"{what} {dist[i]:.2f} m from the object{why}",
                         float(dist[i]), float(cost[i]), in_sight, room)
    # No seen free floor within reach is reachable: a traversable unknown cell within reach, said so
    # (the map may have missed the floor in an occlusion shadow; on_map reports such a goal as not ok).
    unseen = (np.isfinite(cm.weights[win].ravel()) & (cm.occ.cells[win].ravel() != FREE) & may[win].ravel()
              & (dist <= cfg.reach) & reach_ok)
    if unseen.any():
        k = unseen & (dist <= cfg.reach - cfg.goal_margin)
        i = _pick(np.nonzero(k if k.any() else unseen)[0], cost, dist, not k.any(), spec.resolution)
        return _pose(rc[i], centres[i], fp, True, f"an unknown cell {dist[i]:.2f} m from the object: no reachable "
                     "cell of seen free floor lies within reach", float(dist[i]), float(cost[i]), None, None,
                     on_seen_floor=False)
    # Out of reach: the reachable seen free cell closest to the object, over the whole grid.
    ok_all = np.isfinite(field) & (cm.occ.cells == FREE) & may
    if not ok_all.any():  # stay where the robot stands rather than stop on floor nobody saw
        xy = spec.to_world(np.asarray(s_cell))
        d0 = float(_distances(xy.reshape(1, 2), fp)[0])
        # Say which it is: the floor within reach was never seen, or the caller ruled out the seen
        # floor it can get to (cells the agent failed to get to, a relaxed level's tight cells).
        ruled_out = bool((np.isfinite(field) & (cm.occ.cells == FREE) & ~may).any())
        why = ("every reachable cell of seen free floor is ruled out as a goal (cells the robot could not get to, "
               "or too tight for it)" if ruled_out else
               "no seen free cell is reachable from the start (only unknown space)")
        return _pose(np.asarray(s_cell), xy, fp, d0 <= cfg.reach, f"{why}; staying {d0:.2f} m from the object",
                     d0, 0.0, None, None)
    r_all = np.argwhere(ok_all)
    c_all = spec.to_world(r_all)
    d_all = _distances(c_all, fp)
    best = d_all.min()
    nearest = np.nonzero(d_all <= best + 0.5 * spec.resolution)[0]
    cost_all = field[r_all[:, 0], r_all[:, 1]] * spec.resolution
    i = int(nearest[np.argmin(cost_all[nearest])])
    why = (f"no reachable free cell within {cfg.reach:.2f} m of the object; closest reachable cell is "
           f"{d_all[i]:.2f} m away")
    if cut_off:
        # Free floor beside the object exists, walled off from the robot on the map: a shut door
        # reads as wall, so does a gap narrower than the robot.
        why += (f" (the free floor within reach of it, {cut_off * spec.resolution ** 2:.2f} m^2, is not connected "
                "to where the robot stands on the map: a closed door or a gap narrower than the robot)")
    return _pose(r_all[i], c_all[i], fp, False, why, float(d_all[i]), float(cost_all[i]), None, None)


def _inside_region(labels: NDArray[np.int32], region: int, radius_cells: float) -> NDArray[np.bool_]:
    """Cells of ``region`` whose robot disk lies in it: not within the robot's radius of another
    region's cell (a doorway is shared by the two rooms it joins; standing in it is in neither)."""
    from scipy import ndimage

    other = (labels >= 0) & (labels != region)
    if not other.any():
        return np.asarray(labels == region)
    return np.asarray((labels == region) & (ndimage.distance_transform_edt(~other) > radius_cells))


def _pick(ok: NDArray[np.intp], cost: NDArray[np.float64], dist: NDArray[np.float64], closest: bool,
          resolution: float) -> int:
    """The cheapest of the candidate cells ``ok``; with ``closest`` the cheapest of those nearest the
    object (within half a cell of the nearest). Without a cell ``goal_margin`` inside the reach, the
    margin that absorbs the mapped footprint's error is what is left: the cheapest cell within
    reach may stand on its very edge (1.00 m from the mapped lamp, 1.03 m from the lamp)."""
    if closest:
        ok = ok[dist[ok] <= dist[ok].min() + 0.5 * resolution]
    return int(ok[np.argmin(cost[ok])])


def _distances(points: NDArray[np.float64], fp: NDArray[np.float64]) -> NDArray[np.float64]:
    return polygon_distance(points, fp)


def polygon_centroid(fp: NDArray[np.float64]) -> NDArray[np.float64]:
    """Area centroid of a simple polygon (the vertex mean is biased where a hull has many vertices);
    the vertex mean for degenerate footprints (a point, a segment, zero area)."""
    if len(fp) >= 3:
        x, y = fp[:, 0], fp[:, 1]
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        cross = x * yn - xn * y
        area = cross.sum() / 2.0
        if abs(area) > 1e-12:
            return np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area)
    return np.asarray(fp.mean(axis=0), dtype=np.float64)


def _pose(cell: NDArray[np.intp], xy: NDArray[np.float64], fp: NDArray[np.float64], within: bool, reason: str,
          dist: float, cost: float, in_sight: bool | None, in_room: bool | None, on_seen_floor: bool = True
          ) -> GoalPose:
    centre = polygon_centroid(fp)
    d = centre - xy
    yaw = float(np.arctan2(d[1], d[0])) if np.hypot(*d) > 1e-9 else 0.0
    return GoalPose(np.asarray(xy, dtype=np.float64), yaw, (int(cell[0]), int(cell[1])), within, reason, dist, cost,
                    in_sight, in_room, on_seen_floor)
