"""Navigation on a map alone: a goal pose and a path for a robot stack, no simulator.

A map of any recording (``capnav import`` + ``capnav map``) knows where its camera went. The
default start is the last camera pose, projected to the floor; the floor under and around the
camera path counts as free (the camera was carried there, though depth rarely sees the floor
right under it); the goal pose near the described object and the A* path are planned on the
mapped occupancy, all in the map's frame. The robot stack that reads the result drives.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import CapNavError, InputError
from capnav.core.grid import FREE, UNKNOWN, OccupancyGrid
from capnav.planning.config import PlannerConfig
from capnav.planning.costmap import build_costmap, locate_start
from capnav.planning.goal import GoalPose, select_goal
from capnav.planning.path import PlannedPath, floor_along, plan_path
from capnav.planning.sight import map_columns, object_heights

if TYPE_CHECKING:
    from capnav.mapping.cmap import CameraTrajectory, CapNavMap
    from capnav.retrieval.query import ParsedQuery
    from capnav.retrieval.result import QueryResult
    from capnav.retrieval.retriever import Retriever

PATH_FREE_RADIUS = 0.3  # m around the camera path counted as free (a person's or robot's width)


def camera_yaw(T_wc: NDArray[np.floating]) -> float:
    """Heading of a camera in a z-up world: its optical axis projected to the floor (or its image-up
    when it looks straight down)."""
    R = np.asarray(T_wc, dtype=np.float64)[:3, :3]
    d = R[:2, 2] if np.hypot(*R[:2, 2]) > 1e-6 else -R[:2, 1]
    return float(np.arctan2(d[1], d[0]))


def camera_start(trajectory: CameraTrajectory | None, where: str = "the map") -> tuple[tuple[float, float, float], str]:
    """The last camera pose on the floor, (x, y, yaw), and a note naming its frame."""
    if trajectory is None or len(trajectory) == 0:
        raise InputError(f"{where} records no camera path (built before CapNav stored it, or from no frame): "
                         "pass --start X,Y[,YAW]")
    T = trajectory.poses[-1]
    return (float(T[0, 3]), float(T[1, 3]), camera_yaw(T)), f"the last camera pose (frame {trajectory.frames[-1]})"


def free_along_path(occ: OccupancyGrid, xy: NDArray[np.floating], radius: float = PATH_FREE_RADIUS
                    ) -> tuple[OccupancyGrid, int]:
    """``occ`` with the unknown cells within ``radius`` of the polyline ``xy`` (N, 2) made free;
    returns the grid and how many cells changed. Cells the depth saw occupied stay occupied."""
    from scipy import ndimage

    s = occ.spec
    p = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    if len(p) == 0 or radius <= 0:
        return occ, 0
    pts = [p[:1]]
    for a, b in pairwise(p):  # sample each segment at half a cell
        n = max(1, int(np.ceil(np.linalg.norm(b - a) / (0.5 * s.resolution))))
        pts.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    rc = s.to_cell(np.concatenate(pts))
    rc = rc[s.inside(rc)]
    if len(rc) == 0:
        return occ, 0
    on = np.zeros(occ.cells.shape, dtype=bool)
    on[rc[:, 0], rc[:, 1]] = True
    near = ndimage.distance_transform_edt(~on) * s.resolution <= radius
    change = near & (occ.cells == UNKNOWN)
    cells = occ.cells.copy()
    cells[change] = FREE
    return OccupancyGrid(s, cells), int(change.sum())


def planning_grid(cmap: CapNavMap, radius: float = PATH_FREE_RADIUS) -> tuple[OccupancyGrid, list[str]]:
    """The grid to plan on for a map: its occupancy with the unknown cells within ``radius`` of the
    camera path counted as free, and a note saying how many (none for a map with no camera path).
    ``capnav navigate``, the library API and the map server all plan on this grid."""
    occ, notes = cmap.occupancy, []
    if cmap.trajectory is not None and len(cmap.trajectory):
        occ, n = free_along_path(occ, cmap.trajectory.poses[:, :2, 3], radius)
        notes.append(f"{n} unknown cells within {radius:.2f} m of the camera path counted as free")
    return occ, notes


@dataclass
class MapNavigation:
    """An instruction answered on a map: the object chosen, the goal pose (x, y, yaw facing the
    object) and the A* path from the start, in the map's frame, or why there is none."""

    instruction: str
    query: QueryResult
    start: tuple[float, float, float]
    start_source: str
    occupancy: OccupancyGrid  # the grid planned on (mapped, plus the camera path made free)
    goal: GoalPose | None = None
    path: PlannedPath | None = None
    reason: str = ""
    notes: list[str] = field(default_factory=list)
    reach: float = PlannerConfig.reach
    through_unknown: bool = False  # a path over unknown space is accepted (else it is not ok)
    seen_free_m: float = 0.0  # of the path's length, over seen free floor ...
    unknown_m: float = 0.0  # ... and over unknown space

    @property
    def ok(self) -> bool:
        """A path to a goal pose within reach of the chosen object, over seen free floor only
        unless ``through_unknown``."""
        return self.path is not None and self.goal is not None and self.goal.reached_within_reach \
            and (self.through_unknown or (self.unknown_m <= 0.0 and self.goal.on_seen_floor))

    def to_dict(self) -> dict[str, Any]:
        g = self.goal
        return {"instruction": self.instruction, "frame": "map", "ok": self.ok, "reason": self.reason,
                "start": {"x": round(self.start[0], 4), "y": round(self.start[1], 4), "yaw": round(self.start[2], 4),
                          "source": self.start_source},
                "goal": None if g is None else {"x": round(float(g.xy[0]), 4), "y": round(float(g.xy[1]), 4),
                                                "yaw": round(g.yaw, 4),
                                                "ok": g.reached_within_reach
                                                and (g.on_seen_floor or self.through_unknown),
                                                **g.to_dict()},
                "path": None if self.path is None else {
                    **self.path.to_dict(), "seen_free_m": round(self.seen_free_m, 4),
                    "unknown_m": round(self.unknown_m, 4),
                    "seen_free_fraction": round(self.seen_free_m / max(self.seen_free_m + self.unknown_m, 1e-12), 4)},
                "notes": list(self.notes),
                "retrieval": self.query.to_dict()}


def navigate_on_map(cmap: CapNavMap, retriever: Retriever, instruction: str | ParsedQuery,
                    start: tuple[float, float, float] | None = None, config: PlannerConfig | None = None,
                    path_free_radius: float = PATH_FREE_RADIUS, through_unknown: bool = False) -> MapNavigation:
    """Retrieve the described object, choose a goal pose within reach of it, plan A* to it.

    Bad input (no start and no camera path, a start off the map or inside an obstacle) raises
    ``InputError``; no object, no goal within reach or no path gives ``ok=False`` with the reason,
    and so does a path that crosses unknown space, unless ``through_unknown``.
    """
    cfg = config or PlannerConfig()
    source = "--start"
    if start is None:
        start, source = camera_start(cmap.trajectory)
    occ, notes = planning_grid(cmap, path_free_radius)
    xy = (start[0], start[1])
    # The robot stands on the floor under it, seen or not.
    occ, n_under = free_along_path(occ, np.array([xy]), cfg.robot_radius)
    if n_under:
        notes.append(f"{n_under} unknown cells under the robot at the start counted as free")
    cm = build_costmap(occ, cfg, map_columns(cmap))
    locate_start(cm, xy, cfg)  # a start off the map or in an obstacle is the user's error: raise now
    query = retriever.query(instruction, robot_xy=xy)
    text = instruction if isinstance(instruction, str) else instruction.text
    out = MapNavigation(text, query, start, source, occ, notes=notes, reach=cfg.reach,
                        through_unknown=through_unknown)
    if not query.found or query.chosen is None:
        out.reason = f"no object chosen: {query.reason}"
        return out
    try:
        out.goal = select_goal(occ, query.chosen.footprint, xy, cfg, cm, z_range=object_heights(query.chosen))
        out.path = plan_path(occ, xy, out.goal.xy, cfg, cm)
    except CapNavError as e:
        out.reason = f"no path to object {query.chosen.id} ({query.chosen.label}): {e}"
        return out
    out.seen_free_m, out.unknown_m = floor_along(occ, out.path.waypoints)
    if (out.unknown_m > 0 or not out.goal.on_seen_floor) and not through_unknown:
        _over_seen_floor(out, occ, query.chosen, xy, cfg, cm.columns)
    out.notes += out.path.notes
    if out.goal.reached_within_reach:
        out.reason = (f"A* path of {out.path.length_m:.2f} m to {out.goal.reason} (grid {cm.spec.resolution:.2f} m, "
                      f"obstacles inflated by {cfg.inflation:.2f} m)")
        if out.unknown_m > 0 or not out.goal.on_seen_floor:
            what = (f"the path crosses {out.unknown_m:.2f} m of unknown space (of {out.path.length_m:.2f} m)"
                    if out.unknown_m > 0 else "the goal stands on unknown space")
            out.reason = (f"{what}: " + ("accepted (--through-unknown); " if through_unknown else
                                         "not planned over floor nobody saw (pass --through-unknown to accept it); ")
                          + out.reason)
    else:
        out.reason = f"the object is out of reach from the start: {out.goal.reason}"
    return out


def _over_seen_floor(out: MapNavigation, occ: OccupancyGrid, chosen: Any, xy: tuple[float, float],
                     cfg: PlannerConfig, columns: Any) -> None:
    """The cheapest path crossed unknown space: plan again with unknown cells blocked, and keep
    that plan when it still ends within reach (else the first stands, reported as not ok)."""
    from dataclasses import replace

    strict = replace(cfg, unknown_cost=None)
    try:
        cm = build_costmap(occ, strict, columns)
        goal = select_goal(occ, chosen.footprint, xy, strict, cm, z_range=object_heights(chosen))
        path = plan_path(occ, xy, goal.xy, strict, cm)
    except CapNavError:
        return
    seen, unknown = floor_along(occ, path.waypoints)
    assert out.goal is not None
    if goal.reached_within_reach and goal.on_seen_floor and (unknown < out.unknown_m or not out.goal.on_seen_floor):
        out.notes.append(f"planned over seen floor: the cheapest path crossed {out.unknown_m:.2f} m of unknown space")
        out.goal, out.path, out.seen_free_m, out.unknown_m = goal, path, seen, unknown


def write_outputs(nav: MapNavigation, cmap: CapNavMap, out_dir: str | Path, stem: str = "navigate"
                  ) -> dict[str, Path]:
    """``<stem>.json`` (start, goal pose, path, object, reasons), ``<stem>.png`` and the planned-on
    grid as a map_server pair ``<stem>_map.pgm`` + ``<stem>_map.yaml``, all in the map's frame."""
    from capnav.core.atomic import write_json
    from capnav.io.rosmap import write_ros_map
    from capnav.viz.topdown import draw_navigation, short_label

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    pgm, yml = write_ros_map(nav.occupancy, out / f"{stem}_map.yaml")
    chosen = nav.query.chosen
    goal = None if nav.goal is None else (*nav.goal.xy, nav.goal.yaw)
    what = short_label(chosen) if chosen is not None else "no object"
    title = f'"{nav.instruction}" -> {what}: ' + (f"path {nav.path.length_m:.1f} m" if nav.ok and nav.path else
                                                   nav.reason[:120])
    cam = None if cmap.trajectory is None else cmap.trajectory.poses[:, :2, 3]
    png = draw_navigation(nav.occupancy, cmap.objects, chosen.id if chosen else None,
                          None if nav.path is None else nav.path.waypoints, None, nav.start, None, title,
                          out / f"{stem}.png", goal=goal, reach=nav.reach, camera_xy=cam)
    js = out / f"{stem}.json"
    write_json(js, {**nav.to_dict(), "map_server": {"yaml": yml.name, "image": pgm.name}})
    return {"json": js, "png": png, "pgm": pgm, "yaml": yml}
