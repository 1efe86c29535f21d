"""From an occupancy grid to the weight grid A* searches, and where start/goal points land on it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.errors import InputError, NotFoundError
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.planning.config import PlannerConfig

if TYPE_CHECKING:
    from capnav.planning.sight import HeightColumns

Cell = tuple[int, int]


@dataclass
class Costmap:
    """``weights`` (rows, cols) float32 (half the memory a search walks): 1 on free cells,
    ``unknown_cost`` on unknown ones, ``inf`` on obstacles grown by the robot radius plus the
    safety margin (and on blocked unknown). Weights may be raised in place (``mark_blocked``)."""

    occ: OccupancyGrid  # the grid as given (not inflated)
    weights: NDArray[np.float32]
    columns: HeightColumns | None = None  # observed heights per cell, for 3D lines of sight (planning/sight.py)
    cache: dict[str, Any] = field(default_factory=dict, repr=False)  # per-map results (room regions)

    @property
    def spec(self) -> GridSpec:
        return self.occ.spec

    def traversable(self) -> NDArray[np.bool_]:
        return np.isfinite(self.weights)


def check_occupancy(occ: object) -> OccupancyGrid:
    """Reject what is not a usable map, with a message that says why."""
    if not isinstance(occ, OccupancyGrid):
        raise InputError(f"expected an OccupancyGrid, got {type(occ).__name__}")
    vals = np.unique(occ.cells)
    bad = vals[~np.isin(vals, (FREE, OCCUPIED, UNKNOWN))]
    if bad.size:
        raise InputError(f"occupancy cells must be FREE/OCCUPIED/UNKNOWN (0/1/2), found values {bad.tolist()}")
    if not (occ.cells == FREE).any():
        raise InputError(
            f"the occupancy map is empty: none of its {occ.cells.size} cells is FREE "
            "(was the map built from any frames?)")
    return occ


def build_costmap(occ: OccupancyGrid, config: PlannerConfig | None = None,
                  columns: HeightColumns | None = None) -> Costmap:
    """Inflate obstacles, add the clearance cost near them and price unknown space; ``columns``
    (the map's observed heights) ride along for goal selection's lines of sight."""
    cfg = config or PlannerConfig()
    occ = check_occupancy(occ)
    obstacle = occ.cells == OCCUPIED
    w = np.ones(occ.cells.shape, np.float32)
    if obstacle.any():
        dist = ndimage.distance_transform_edt(~obstacle) * occ.spec.resolution
        if cfg.clearance_cost > 0 and cfg.clearance_band > 0:
            w += cfg.clearance_cost * np.clip(1.0 - (dist - cfg.inflation) / cfg.clearance_band, 0.0, 1.0)
        w[dist <= cfg.inflation] = np.inf
    unknown = occ.cells == UNKNOWN
    w[unknown] = np.inf if cfg.unknown_cost is None else np.maximum(w[unknown], cfg.unknown_cost)
    w[obstacle] = np.inf
    return Costmap(OccupancyGrid(occ.spec, occ.cells.copy()), w, columns)


def mark_blocked(costmap: Costmap, xy: NDArray[np.floating], radius: float, config: PlannerConfig,
                 robot_xy: NDArray[np.floating] | None = None) -> int:
    """Record an obstacle found by contact: a disk at ``xy`` becomes OCCUPIED, and its inflation
    becomes untraversable. Returns the number of newly blocked cells.

    The disk the robot stands on (``robot_xy``, robot radius) is never marked: the robot is
    physically there, so it is free, and marking it would leave the robot "inside an obstacle".
    """
    spec = costmap.spec
    rc = spec.to_cell(np.asarray(xy, dtype=np.float64))
    reach = radius + config.inflation
    k = int(np.ceil(reach / spec.resolution)) + 1
    r0, r1 = max(rc[0] - k, 0), min(rc[0] + k + 1, spec.rows)
    c0, c1 = max(rc[1] - k, 0), min(rc[1] + k + 1, spec.cols)
    if r0 >= r1 or c0 >= c1:
        return 0
    rr, cc = np.mgrid[r0:r1, c0:c1]
    centres = spec.to_world(np.stack([rr, cc], axis=-1))
    d = np.linalg.norm(centres - np.asarray(xy, dtype=np.float64), axis=-1)
    keep = np.zeros(d.shape, dtype=bool)
    if robot_xy is not None:
        keep = np.linalg.norm(centres - np.asarray(robot_xy, dtype=np.float64), axis=-1) <= config.robot_radius
    costmap.occ.cells[r0:r1, c0:c1][(d <= radius) & ~keep] = OCCUPIED
    win = costmap.weights[r0:r1, c0:c1]
    newly = (d <= reach) & np.isfinite(win) & ~keep
    win[newly] = np.inf
    costmap.cache.pop("goal_around", None)  # goal selection's per-object windows read the cells marked here
    costmap.cache.pop("goal_pose", None)  # and the poses it chose on the weights before the mark
    costmap.cache.pop("goal_field", None)  # and the fields of the cells that passed the goal rule
    costmap.cache.pop("goal_field_asked", None)
    costmap.cache.pop("goal_walk_base", None)  # the weights those fields were walked on
    return int(newly.sum())


def locate(costmap: Costmap, xy: NDArray[np.floating] | tuple[float, float], what: str) -> Cell:
    """The cell under a world point; ``InputError`` when the point is off the map or not finite."""
    p = np.asarray(xy, dtype=np.float64).reshape(-1)
    if p.shape != (2,) or not np.isfinite(p).all():
        raise InputError(f"{what} must be a finite (x, y) pair, got {xy!r}")
    rc = costmap.spec.to_cell(p)
    if not costmap.spec.inside(rc):
        s = costmap.spec
        raise InputError(
            f"{what} ({p[0]:.2f}, {p[1]:.2f}) is off the map, which covers x in [{s.x0:.2f}, "
            f"{s.x0 + s.cols * s.resolution:.2f}], y in [{s.y0:.2f}, {s.y0 + s.rows * s.resolution:.2f}]")
    return int(rc[0]), int(rc[1])


def locate_start(costmap: Costmap, xy: NDArray[np.floating] | tuple[float, float], config: PlannerConfig
                 ) -> tuple[Cell, str]:
    """The start cell, snapped to the nearest traversable cell when the robot stands in the
    inflation band or in unknown space (a robot is often closer to a wall than radius + margin).

    Returns the cell and a note (empty unless snapped). A start inside an obstacle is an error.
    """
    rc = locate(costmap, xy, "start")
    p = np.asarray(xy, dtype=np.float64).reshape(2)
    if costmap.occ.cells[rc] == OCCUPIED:
        raise InputError(f"start ({p[0]:.2f}, {p[1]:.2f}) is inside an obstacle (cell {rc[0]}, {rc[1]})")
    if np.isfinite(costmap.weights[rc]):
        return rc, ""
    res = costmap.spec.resolution
    k = int(np.ceil(config.escape_radius / res)) + 1
    r0, c0 = max(rc[0] - k, 0), max(rc[1] - k, 0)
    win = costmap.weights[r0:rc[0] + k + 1, c0:rc[1] + k + 1]
    ok = np.isfinite(win)
    if ok.any():
        # Distance from every window cell to the nearest traversable one, with its index.
        _, (ir, ic) = ndimage.distance_transform_edt(~ok, return_indices=True)
        lr, lc = rc[0] - r0, rc[1] - c0
        cell = (int(ir[lr, lc]) + r0, int(ic[lr, lc]) + c0)
        dist = float(np.hypot(cell[0] - rc[0], cell[1] - rc[1]) * res)
        if dist <= config.escape_radius:
            return cell, (f"start ({p[0]:.2f}, {p[1]:.2f}) lies within {config.inflation:.2f} m of an obstacle "
                          f"or in unknown space; snapped {dist:.2f} m to the nearest free cell")
    raise InputError(
        f"start ({p[0]:.2f}, {p[1]:.2f}) has no free cell within {config.escape_radius:.2f} m once obstacles are "
        f"inflated by {config.inflation:.2f} m (robot radius + margin)")


def locate_goal(costmap: Costmap, xy: NDArray[np.floating] | tuple[float, float]) -> Cell:
    """The goal cell; ``NotFoundError`` when it is blocked (an obstacle or too close to one)."""
    rc = locate(costmap, xy, "goal")
    if not np.isfinite(costmap.weights[rc]):
        p = np.asarray(xy, dtype=np.float64).reshape(2)
        why = "inside an obstacle" if costmap.occ.cells[rc] == OCCUPIED else "too close to an obstacle or unknown"
        raise NotFoundError(f"goal ({p[0]:.2f}, {p[1]:.2f}) is unreachable: it is {why}")
    return rc
