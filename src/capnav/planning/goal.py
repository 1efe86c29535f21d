"""Goal selection (Sec. 3.4): the chosen object's footprint becomes a reachable metric waypoint.

The paper turns the object's cell into a waypoint; an object's own cell is an obstacle, so we pick
the free cell nearest to the robot (by path cost) among those within the reach radius of the
footprint, aiming ``goal_margin`` inside it when possible, and face the object from there. Within
1 m of an object may lie behind its wall, so cells that see the object on the map come first
(``PlannerConfig.prefer_line_of_sight``, see :mod:`capnav.planning.sight`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, NotFoundError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import OccupancyGrid
from capnav.planning.config import PlannerConfig
from capnav.planning.costmap import Costmap, build_costmap, locate_start
from capnav.planning.search import cost_field
from capnav.planning.sight import sees_footprint


@dataclass(frozen=True)
class GoalPose:
    """Where to stop: ``xy`` world, ``yaw`` facing the object, its grid ``cell``; whether it lies
    within ``reach`` of the footprint, why it was chosen, and its distance / path cost (m)."""

    xy: NDArray[np.float64]
    yaw: float
    cell: tuple[int, int]
    reached_within_reach: bool
    reason: str
    distance_to_object: float
    path_cost: float

    def to_dict(self) -> dict[str, Any]:
        return {"xy": [round(float(v), 4) for v in self.xy], "yaw": round(self.yaw, 4), "cell": list(self.cell),
                "reached_within_reach": self.reached_within_reach, "reason": self.reason,
                "distance_to_object": round(self.distance_to_object, 4), "path_cost": round(self.path_cost, 4)}


def check_footprint(footprint: object) -> NDArray[np.float64]:
    fp = np.asarray(footprint, dtype=np.float64)
    if fp.ndim != 2 or fp.shape[1] != 2 or len(fp) == 0:
        raise InputError(f"target footprint must be a (K, 2) array of world x, y, got shape {fp.shape}")
    if not np.isfinite(fp).all():
        raise InputError("target footprint has non-finite coordinates")
    return fp


def select_goal(occ: OccupancyGrid, target_footprint: NDArray[np.floating], start_xy: Any,
                config: PlannerConfig | None = None, costmap: Costmap | None = None) -> GoalPose:
    """Nearest reachable free cell within ``reach - goal_margin`` of the footprint; else, among the
    cells within ``config.reach``, the nearest reachable one of those closest to the object (the
    margin left absorbs the mapped footprint's error); else the reachable cell closest to the
    object, with the reason.

    With ``config.prefer_line_of_sight`` the same two tiers are first tried among the cells that
    see the footprint on the map; when none within reach does, the reason says so.

    Raises ``NotFoundError`` when nothing at all is reachable from the start.
    """
    cfg = config or PlannerConfig()
    fp = check_footprint(target_footprint)
    cm = costmap if costmap is not None else build_costmap(occ, cfg)
    spec = cm.spec
    s_cell, _ = locate_start(cm, start_xy, cfg)
    field, _ = cost_field(cm.weights, s_cell)
    reach_r, reach_c = np.nonzero(np.isfinite(field))
    rc = np.stack([reach_r, reach_c], axis=1)
    centres = spec.to_world(rc)
    cost = field[reach_r, reach_c] * spec.resolution
    # Only cells in the footprint's box grown by the reach can be within reach: measure those.
    lo, hi = fp.min(axis=0) - cfg.reach, fp.max(axis=0) + cfg.reach
    near = np.nonzero(((centres >= lo) & (centres <= hi)).all(axis=1))[0]
    dist = np.full(len(rc), np.inf)
    dist[near] = _distances(centres[near], fp)
    tiers = ((cfg.reach - cfg.goal_margin, "the nearest reachable free cell {d:.2f} m from the object"),
             (cfg.reach, "the nearest reachable free cell within reach ({d:.2f} m from the object; none "
                         f"within {cfg.reach - cfg.goal_margin:.2f} m)"))
    within = np.nonzero(dist <= cfg.reach)[0]
    blind = ""
    if cfg.prefer_line_of_sight and within.size:
        seen = np.zeros(len(rc), dtype=bool)
        seen[within] = sees_footprint(cm.occ, fp, rc[within], polygon_centroid(fp))
        for k, (limit, why) in enumerate(tiers):
            ok = np.nonzero(seen & (dist <= limit))[0]
            if ok.size:
                i = _pick(ok, cost, dist, k > 0, spec.resolution)
                return _pose(rc[i], centres[i], fp, True, why.format(d=dist[i]) + ", in sight of it on the map",
                             float(dist[i]), float(cost[i]))
        blind = f"; none of the {within.size} reachable cells within reach sees the object on the map"
    for k, (limit, why) in enumerate(tiers):
        ok = np.nonzero(dist <= limit)[0]
        if ok.size:
            i = _pick(ok, cost, dist, k > 0, spec.resolution)
            return _pose(rc[i], centres[i], fp, True, why.format(d=dist[i]) + blind, float(dist[i]), float(cost[i]))
    if len(rc) == 0:  # pragma: no cover - the start cell itself is always reachable
        raise NotFoundError("no cell is reachable from the start")
    dist = _distances(centres, fp)
    best = dist.min()
    ok = np.nonzero(dist <= best + 0.5 * spec.resolution)[0]
    i = int(ok[np.argmin(cost[ok])])
    why = (f"no reachable free cell within {cfg.reach:.2f} m of the object; closest reachable cell is "
           f"{dist[i]:.2f} m away")
    return _pose(rc[i], centres[i], fp, False, why, float(dist[i]), float(cost[i]))


def _pick(ok: NDArray[np.intp], cost: NDArray[np.float64], dist: NDArray[np.float64], closest: bool,
          resolution: float) -> int:
    """The cheapest of the candidate cells ``ok``; with ``closest`` the cheapest of those nearest the
    object (within half a cell of the nearest). Without a cell ``goal_margin`` inside the reach, the
    margin that absorbs the mapped footprint's error is what is left: the cheapest cell within
    reach may stand on its very edge (1.00 m from the mapped lamp, 1.03 m from the lamp)."""
    if closest:
        ok = ok[dist[ok] <= dist[ok].min() + 0.5 * resolution]
    return int(ok[np.argmin(cost[ok])])


def _distances(points: NDArray[np.float64], fp: NDArray[np.float64], chunk: int = 65536) -> NDArray[np.float64]:
    """Footprint distance in chunks so a large map never builds a huge (N, K, 2) temporary."""
    out = np.empty(len(points), np.float64)
    for a in range(0, len(points), chunk):
        out[a:a + chunk] = footprint_distance(points[a:a + chunk], fp)
    return out


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
          dist: float, cost: float) -> GoalPose:
    centre = polygon_centroid(fp)
    d = centre - xy
    yaw = float(np.arctan2(d[1], d[0])) if np.hypot(*d) > 1e-9 else 0.0
    return GoalPose(np.asarray(xy, dtype=np.float64), yaw, (int(cell[0]), int(cell[1])), within, reason, dist, cost)
