"""The goal a person would choose: seen free floor, the object's room, 3D sight from eye height."""

from __future__ import annotations

import numpy as np

from capnav.core.footprint import footprint_distance
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.planning import PlannerConfig, build_costmap, select_goal
from capnav.planning.goal import polygon_centroid
from capnav.planning.nearest import NearestSearch
from capnav.planning.search import cost_field
from capnav.planning.sight import HeightColumns, sees_footprint

RES = 0.05


def box(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def solid(spec: GridSpec, fp: np.ndarray, z0: float, z1: float) -> np.ndarray:
    """Surface points filling a box (a mapped piece of furniture or wall), one per cell and voxel layer."""
    lo, hi = fp.min(axis=0), fp.max(axis=0)
    xs = np.arange(lo[0] + RES / 2, hi[0], RES)
    ys = np.arange(lo[1] + RES / 2, hi[1], RES)
    zs = np.arange(max(z0, 0.0) + RES / 2, z1, RES)
    g = np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3)
    return g


def world(w: float, h: float, parts: list[tuple[np.ndarray, float, float]]) -> tuple[OccupancyGrid, HeightColumns]:
    """A w x h m floor with walls around it and ``parts`` (footprint, z0, z1): occupied in 2D where a
    part reaches into the obstacle band, and in the columns at its heights."""
    spec = GridSpec(0.0, 0.0, RES, round(h / RES), round(w / RES))
    parts = [*parts, (box(0, 0, w, 0.1), 0, 2.6), (box(0, h - 0.1, w, h), 0, 2.6), (box(0, 0, 0.1, h), 0, 2.6),
             (box(w - 0.1, 0, w, h), 0, 2.6)]
    pts = np.concatenate([solid(spec, fp, z0, z1) for fp, z0, z1 in parts])
    cols = HeightColumns.from_points(spec, pts)
    cells = np.where(cols.masks != 0, OCCUPIED, FREE).astype(np.uint8)
    return OccupancyGrid(spec, cells), cols


# A TV on the north wall (1.0-1.6 m up) above a 0.8 m cabinet standing against the wall.
TV = box(1.6, 3.85, 2.4, 3.9)
CABINET = box(1.4, 3.5, 2.6, 3.9)


def tv_room(cabinet_top: float = 0.8) -> tuple[OccupancyGrid, HeightColumns]:
    return world(4.0, 4.0, [(CABINET, 0.0, cabinet_top), (TV, 1.0, 1.6), (box(0, 3.9, 4.0, 4.0), 0.0, 2.6)])


def test_a_tv_above_a_cabinet_is_seen_over_it_from_eye_height() -> None:
    occ, cols = tv_room()
    cm = build_costmap(occ, PlannerConfig(), cols)
    goal = select_goal(occ, TV, (2.0, 1.0), PlannerConfig(), cm, z_range=(1.0, 1.6))
    assert goal.reached_within_reach and goal.in_sight is True and "in sight" in goal.reason
    assert goal.distance_to_object <= 0.7 + 1e-9 and abs(goal.yaw - np.pi / 2) < 0.3  # faces the wall
    # The flat test sees the cabinet's cells in the way at every height: no cell in front sees the TV.
    cell = np.array([goal.cell])
    assert not sees_footprint(occ, TV, cell, polygon_centroid(TV))[0]
    assert sees_footprint(occ, TV, cell, polygon_centroid(TV), cols, (1.0, 1.6))[0]
    flat = select_goal(occ, TV, (2.0, 1.0), PlannerConfig(), build_costmap(occ, PlannerConfig()), z_range=(1.0, 1.6))
    assert flat.in_sight is False and "out of sight" in flat.reason


def test_a_wardrobe_taller_than_the_eye_hides_the_tv() -> None:
    occ, cols = tv_room(cabinet_top=2.0)
    cm = build_costmap(occ, PlannerConfig(), cols)
    goal = select_goal(occ, TV, (2.0, 1.0), PlannerConfig(), cm, z_range=(1.0, 1.6))
    assert goal.reached_within_reach and goal.in_sight is False and "out of sight" in goal.reason


def two_rooms() -> tuple[OccupancyGrid, HeightColumns]:
    """West and east rooms of 3 m x 6 m split by a wall at x = 3.0-3.1 m with a 0.9 m door at y 3.9-4.8."""
    return world(6.0, 6.0, [(box(3.0, 0.0, 3.1, 3.9), 0, 2.6), (box(3.0, 4.8, 3.1, 6.0), 0, 2.6)])


def test_an_object_seen_through_a_doorway_is_reached_in_its_own_room() -> None:
    occ, cols = two_rooms()
    obj = box(3.3, 3.3, 3.6, 3.7)  # in the east room, just south of the door
    occ.cells[occ.spec.to_cell(np.array([3.45, 3.5]))[0] + np.arange(-3, 4)[:, None],
              occ.spec.to_cell(np.array([3.45, 3.5]))[1] + np.arange(-2, 3)[None, :]] = OCCUPIED
    cm = build_costmap(occ, PlannerConfig(), cols)
    start = (1.0, 4.3)
    # A west-room cell by the door is within reach and sees the object through the opening ...
    west = occ.spec.to_cell(np.array([[2.65, 4.3]]))
    assert footprint_distance(occ.spec.to_world(west), obj)[0] <= 1.0
    assert sees_footprint(occ, obj, west, polygon_centroid(obj), cols, (0.0, 0.8))[0]
    # ... but the goal is in the east room, the object's, on its open side.
    goal = select_goal(occ, obj, start, PlannerConfig(), cm, z_range=(0.0, 0.8))
    assert goal.xy[0] > 3.1 and goal.in_room is True and goal.in_sight is True
    assert "in the object's room" in goal.reason and goal.distance_to_object <= 0.7 + 1e-9
    paper = select_goal(occ, obj, start, PlannerConfig(prefer_line_of_sight=False), cm)
    assert paper.xy[0] < 3.0 and paper.path_cost < goal.path_cost  # the old rule stops in the doorway's west side


def test_unknown_floor_behind_a_wall_is_never_a_goal() -> None:
    occ, cols = world(6.0, 9.0, [(box(3.0, 0.0, 3.1, 7.5), 0, 2.6)])  # door at the far north end
    obj = box(3.15, 1.0, 3.5, 1.5)
    rc = np.argwhere(np.ones_like(occ.cells, dtype=bool))
    centres = occ.spec.to_world(rc)
    inside = footprint_distance(centres, obj) == 0
    occ.cells[rc[inside, 0], rc[inside, 1]] = OCCUPIED
    west = (centres[:, 0] > 2.0) & (centres[:, 0] < 3.0) & (centres[:, 1] < 3.0)
    occ.cells[rc[west, 0], rc[west, 1]] = UNKNOWN  # nobody saw the floor west of the wall
    cm = build_costmap(occ, PlannerConfig(), cols)
    goal = select_goal(occ, obj, (1.0, 1.25), PlannerConfig(), cm, z_range=(0.0, 1.0))
    assert occ.cells[goal.cell] == FREE and goal.xy[0] > 3.1 and goal.in_sight and goal.in_room
    # The unknown cells across the wall are nearer by path and within reach: the paper's rule (which
    # allowed unknown cells) would have taken one; with seen floor required, even it does not.
    paper = select_goal(occ, obj, (1.0, 1.25), PlannerConfig(prefer_line_of_sight=False), cm)
    assert occ.cells[paper.cell] == FREE


def test_the_search_settles_targets_in_cost_order_without_the_whole_grid() -> None:
    occ, _ = two_rooms()
    cm = build_costmap(occ, PlannerConfig())
    s = (20, 20)
    target = np.zeros(occ.cells.shape, dtype=bool)
    target[60:70, 80:90] = True
    target &= np.isfinite(cm.weights)
    search = NearestSearch(cm.weights, s, target, (60, 80, 69, 89))
    field, _ = cost_field(cm.weights, s)
    got = []
    while (hit := search.next()) is not None:
        got.append(hit)
        if len(got) == 1:
            assert int((search.state == 2).sum()) < 0.8 * np.isfinite(field).sum()
    costs = [g for _, g in got]
    assert len(got) == int(target.sum()) and costs == sorted(costs)
    assert np.allclose(costs, [field[c] for c, _ in got])
    done = search.finish()
    assert np.allclose(done[np.isfinite(field)], field[np.isfinite(field)])


def test_unseen_space_beyond_the_outer_wall_is_no_room_of_an_object_in_the_corner() -> None:
    # A 4 x 4 m room mapped inside 1.5 m of unknown space (nobody saw beyond its walls); a lamp
    # stands in its corner, its mapped box reaching into the walls. The space outside is no room
    # the lamp is reached from: the goal is in the room, and said so.
    pad, wall, side = 1.5, 0.1, 4.0
    n = round((side + 2 * (pad + wall)) / RES)
    spec = GridSpec(-pad - wall, -pad - wall, RES, n, n)
    c = spec.to_world(np.stack(np.mgrid[0:n, 0:n], axis=-1).reshape(-1, 2)).reshape(n, n, 2)
    inside = (c[..., 0] > 0) & (c[..., 0] < side) & (c[..., 1] > 0) & (c[..., 1] < side)
    walls = (c[..., 0] > -wall) & (c[..., 0] < side + wall) & (c[..., 1] > -wall) & (c[..., 1] < side + wall)
    lamp = box(3.55, 3.55, 4.05, 4.05)
    on_lamp = (c[..., 0] >= 3.55) & (c[..., 0] <= 4.05) & (c[..., 1] >= 3.55) & (c[..., 1] <= 4.05)
    cells = np.where(inside & ~on_lamp, FREE, np.where(walls, OCCUPIED, UNKNOWN)).astype(np.uint8)
    occ = OccupancyGrid(spec, cells)
    goal = select_goal(occ, lamp, (1.0, 1.0))
    assert goal.reached_within_reach and goal.in_room is True, goal.reason
    assert "in the object's room" in goal.reason
