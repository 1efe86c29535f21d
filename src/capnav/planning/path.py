"""A* from a world start to a world goal on an occupancy grid, simplified to waypoints."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import NotFoundError
from capnav.core.grid import FREE, OccupancyGrid
from capnav.planning.backends import BACKENDS
from capnav.planning.config import PlannerConfig
from capnav.planning.costmap import Costmap, build_costmap, locate_goal, locate_start
from capnav.planning.search import simplify

XY = NDArray[np.floating] | tuple[float, float]


@dataclass
class PlannedPath:
    """``cells`` (K, 2) row, col of the optimal grid path; ``waypoints`` (M, 2) world x, y from the
    exact start to the exact goal with straight, obstacle-free segments between them; ``cost`` the
    A* cost in metres (free cells weigh 1, unknown ones ``unknown_cost``); ``length_m`` the length
    of the waypoint polyline, i.e. what the robot drives."""

    cells: NDArray[np.intp]
    waypoints: NDArray[np.float64]
    cost: float
    length_m: float
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {"waypoints": np.round(self.waypoints, 4).tolist(), "cost": round(self.cost, 4),
                "length_m": round(self.length_m, 4), "n_cells": len(self.cells), "notes": list(self.notes)}


def polyline_length(xy: NDArray[np.floating]) -> float:
    return float(np.linalg.norm(np.diff(np.asarray(xy, dtype=np.float64), axis=0), axis=1).sum()) if len(xy) > 1 \
        else 0.0


def floor_along(occ: OccupancyGrid, waypoints: NDArray[np.floating]) -> tuple[float, float]:
    """Metres of the polyline ``waypoints`` (M, 2) over seen free floor and over unknown space
    (sampled at a tenth of a cell; off-map and occupied samples count as unknown). A one-cell
    unsampled gap between seen cells counts as seen (:func:`capnav.language.rooms.fill_gaps`)."""
    from capnav.language.rooms import fill_gaps

    p = np.asarray(waypoints, dtype=np.float64).reshape(-1, 2)
    if len(p) < 2:
        return 0.0, 0.0
    cells = fill_gaps(occ.cells)
    seen = unknown = 0.0
    step = 0.1 * occ.spec.resolution
    for a, b in itertools.pairwise(p):
        length = float(np.linalg.norm(b - a))
        if length <= 0:
            continue
        n = max(1, int(np.ceil(length / step)))
        mid = a + (b - a) * ((np.arange(n) + 0.5) / n)[:, None]
        rc = occ.spec.to_cell(mid)
        ok = occ.spec.inside(rc)
        free = np.zeros(n, dtype=bool)
        free[ok] = cells[rc[ok, 0], rc[ok, 1]] == FREE
        seen += length * float(free.mean())
        unknown += length * float(1.0 - free.mean())
    return seen, unknown


def plan_path(occ: OccupancyGrid, start_xy: XY, goal_xy: XY, config: PlannerConfig | None = None,
              costmap: Costmap | None = None) -> PlannedPath:
    """Plan from ``start_xy`` to ``goal_xy``.

    Raises ``InputError`` when the start is inside an obstacle, a point is off the map or the map
    has no free cell, and ``NotFoundError`` when the goal is blocked or not connected to the start.
    Pass ``costmap`` (from :func:`build_costmap`) to reuse an inflated map across many plans.
    """
    cfg = config or PlannerConfig()
    cm = costmap if costmap is not None else build_costmap(occ, cfg)
    s_cell, note = locate_start(cm, start_xy, cfg)
    g_cell = locate_goal(cm, goal_xy)
    search = BACKENDS.create(cfg.backend)
    cells, cost = search(cm.weights, s_cell, g_cell)
    if len(cells) == 0:
        g = np.asarray(goal_xy, dtype=np.float64).reshape(2)
        raise NotFoundError(
            f"goal ({g[0]:.2f}, {g[1]:.2f}) is not connected to the start on this map "
            f"(obstacles inflated by {cfg.inflation:.2f} m, unknown cells "
            f"{'blocked' if cfg.unknown_cost is None else f'cost {cfg.unknown_cost:g}'})")
    keep = simplify(cm.weights, cells) if cfg.simplify else np.arange(len(cells))
    spec = cm.spec
    start = np.asarray(start_xy, dtype=np.float64).reshape(1, 2)
    goal = np.asarray(goal_xy, dtype=np.float64).reshape(1, 2)
    inner = spec.to_world(cells[keep])
    # The exact start and goal replace their cell centres, unless the start was snapped out of
    # the inflation band: then the robot first drives to the free cell's centre.
    inner = inner[1:-1] if note == "" else inner[:-1]
    wps = np.concatenate([start, inner, goal], axis=0)
    wps = wps[np.r_[True, np.linalg.norm(np.diff(wps, axis=0), axis=1) > 1e-9]]
    notes = [note] if note else []
    return PlannedPath(cells, wps, cost * spec.resolution, polyline_length(wps), notes)
