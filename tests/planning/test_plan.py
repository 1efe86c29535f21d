"""plan_path and select_goal on hand-built grids: inflation, unknown space, bad input, fallbacks."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from capnav.core.errors import InputError, NotFoundError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.planning import PlannerConfig, build_costmap, plan_path, select_goal

RES = 0.05


def room(rows: int = 100, cols: int = 120) -> OccupancyGrid:
    """A walled 6 m x 5 m room."""
    cells = np.zeros((rows, cols), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = OCCUPIED
    return OccupancyGrid(GridSpec(0.0, 0.0, RES, rows, cols), cells)


def wall_with_gap(gap_m: float) -> OccupancyGrid:
    """A wall across x = 3 m with a centred door ``gap_m`` wide."""
    occ = room()
    gap = round(gap_m / RES)
    lo = (100 - gap) // 2
    occ.cells[:, 60] = OCCUPIED
    occ.cells[lo:lo + gap, 60] = 0
    return occ


def clearance(occ: OccupancyGrid, xy: np.ndarray) -> np.ndarray:
    """Distance (m) from points to the nearest OCCUPIED cell centre."""
    obst = occ.spec.to_world(np.argwhere(occ.cells == OCCUPIED))
    return np.min(np.linalg.norm(xy[:, None, :] - obst[None, :, :], axis=-1), axis=1)


def densify(wps: np.ndarray, step: float = 0.01) -> np.ndarray:
    pts = [wps[0]]
    for a, b in itertools.pairwise(wps):
        n = max(int(np.ceil(np.linalg.norm(b - a) / step)), 1)
        pts.extend(a + (b - a) * t for t in np.linspace(0, 1, n + 1)[1:])
    return np.asarray(pts)


def test_path_keeps_clear_of_inflated_obstacles() -> None:
    occ = wall_with_gap(1.0)
    cfg = PlannerConfig(robot_radius=0.2, safety_margin=0.05)
    path = plan_path(occ, (1.0, 1.0), (5.0, 4.0), cfg)
    assert np.allclose(path.waypoints[0], (1.0, 1.0)) and np.allclose(path.waypoints[-1], (5.0, 4.0))
    # Every point driven along the waypoints stays at least the inflation (minus half a cell) away.
    assert clearance(occ, densify(path.waypoints)).min() >= cfg.inflation - RES / 2 - 1e-9
    assert path.length_m <= path.cost + 1e-9  # straight segments are never longer than the grid path
    assert len(path.waypoints) < len(path.cells) / 5


def test_inflation_closes_a_door_narrower_than_the_robot() -> None:
    cfg = PlannerConfig(robot_radius=0.2, safety_margin=0.05)
    plan_path(wall_with_gap(0.7), (1.0, 2.5), (5.0, 2.5), cfg)  # 0.7 m > 2 * 0.25 m: passable
    with pytest.raises(NotFoundError, match="not connected"):
        plan_path(wall_with_gap(0.4), (1.0, 2.5), (5.0, 2.5), cfg)
    # Without inflation the same door is wide enough.
    plan_path(wall_with_gap(0.4), (1.0, 2.5), (5.0, 2.5), PlannerConfig(robot_radius=0.0, safety_margin=0.0))


def test_unknown_cells_blocked_or_costly() -> None:
    occ = room()
    occ.cells[:, 55:65] = UNKNOWN  # an unexplored band across the room
    with pytest.raises(NotFoundError):
        plan_path(occ, (1.0, 2.5), (5.0, 2.5), PlannerConfig(unknown_cost=None))
    cheap = plan_path(occ, (1.0, 2.5), (5.0, 2.5), PlannerConfig(unknown_cost=1.0))
    dear = plan_path(occ, (1.0, 2.5), (5.0, 2.5), PlannerConfig(unknown_cost=4.0))
    assert dear.cost == pytest.approx(cheap.cost + 3.0 * 10 * RES, rel=1e-6)


def test_costly_unknown_is_avoided_when_a_detour_is_cheap() -> None:
    occ = room()
    occ.cells[20:80, 55:65] = UNKNOWN  # an unknown block with free space around it
    path = plan_path(occ, (1.0, 2.5), (5.0, 2.5), PlannerConfig(unknown_cost=5.0))
    cells = occ.spec.to_cell(densify(path.waypoints))
    assert not (occ.cells[cells[:, 0], cells[:, 1]] == UNKNOWN).any()


def test_bad_input_messages() -> None:
    occ = wall_with_gap(1.0)
    with pytest.raises(InputError, match="off the map"):
        plan_path(occ, (1.0, 1.0), (9.0, 9.0))
    with pytest.raises(InputError, match="inside an obstacle"):
        plan_path(occ, (3.02, 0.5), (5.0, 1.0))
    with pytest.raises(InputError, match="empty"):
        empty = OccupancyGrid(occ.spec, np.full_like(occ.cells, UNKNOWN))
        plan_path(empty, (1.0, 1.0), (2.0, 2.0))
    with pytest.raises(NotFoundError, match="obstacle"):
        plan_path(occ, (1.0, 1.0), (3.02, 0.5))
    with pytest.raises(InputError, match="finite"):
        plan_path(occ, (np.nan, 1.0), (2.0, 2.0))
    with pytest.raises(InputError, match="unknown grid search backend"):
        plan_path(occ, (1.0, 1.0), (2.0, 2.0), PlannerConfig(backend="nope"))
    with pytest.raises(InputError):
        PlannerConfig(unknown_cost=0.5)


def test_start_in_inflation_band_snaps_with_a_note() -> None:
    occ = room()
    path = plan_path(occ, (0.12, 2.5), (3.0, 2.5))  # 0.07 m from the wall's cell
    assert path.notes and "snapped" in path.notes[0]
    assert np.allclose(path.waypoints[0], (0.12, 2.5))
    assert np.isfinite(build_costmap(occ).weights[tuple(path.cells[0])])


def test_goal_within_reach_and_facing_the_object() -> None:
    occ = room()
    table = np.array([[4.0, 2.0], [5.0, 2.0], [5.0, 3.0], [4.0, 3.0]])
    r0, c0 = occ.spec.to_cell(table.min(axis=0))
    r1, c1 = occ.spec.to_cell(table.max(axis=0))
    occ.cells[r0:r1, c0:c1] = OCCUPIED
    cfg = PlannerConfig()
    goal = select_goal(occ, table, (1.0, 2.5), cfg)
    assert goal.reached_within_reach
    d = footprint_distance(goal.xy[None], table)[0]
    assert d == pytest.approx(goal.distance_to_object) and d <= cfg.reach - cfg.goal_margin
    assert goal.xy[0] < 4.0  # approached from the robot's side
    centre = table.mean(axis=0)
    assert goal.yaw == pytest.approx(np.arctan2(centre[1] - goal.xy[1], centre[0] - goal.xy[0]))
    # The goal is plannable from the start.
    plan_path(occ, (1.0, 2.5), goal.xy, cfg)


def test_goal_falls_back_to_closest_reachable_cell() -> None:
    occ = wall_with_gap(0.0)  # the right half is cut off
    far = np.array([[5.5, 2.0], [5.8, 2.0], [5.8, 2.3], [5.5, 2.3]])
    goal = select_goal(occ, far, (1.0, 2.5))
    assert not goal.reached_within_reach
    assert "no reachable free cell within 1.00 m" in goal.reason
    assert goal.xy[0] < 3.0 and goal.distance_to_object > 2.0


def test_goal_prefers_the_near_side_of_a_wall() -> None:
    # An object right behind a wall: within 1 m through the wall, but the robot must walk round.
    occ = wall_with_gap(1.0)
    obj = np.array([[3.2, 0.5], [3.6, 0.5], [3.6, 0.9], [3.2, 0.9]])
    goal = select_goal(occ, obj, (1.0, 0.5), PlannerConfig(prefer_line_of_sight=False))
    assert goal.reached_within_reach
    assert goal.xy[0] < 3.0  # the paper's rule: the cheaper cell on the robot's side of the wall
    seen = select_goal(occ, obj, (1.0, 0.5))
    assert seen.reached_within_reach and seen.xy[0] > 3.0  # by default: round the wall, in sight of it


def test_bad_footprint() -> None:
    with pytest.raises(InputError, match=r"\(K, 2\)"):
        select_goal(room(), np.zeros((3,)), (1.0, 1.0))


def test_clearance_cost_centres_the_path_in_a_corridor() -> None:
    occ = room()
    occ.cells[:40, 30:90] = OCCUPIED  # a 0.95 m wide corridor between y = 2.0 and the top wall
    occ.cells[60:, 30:90] = OCCUPIED
    start, goal = (0.5, 2.5), (5.5, 2.5)
    hug = plan_path(occ, (0.5, 2.15), (5.5, 2.15), PlannerConfig(clearance_cost=0.0))
    mid = plan_path(occ, (0.5, 2.15), (5.5, 2.15), PlannerConfig(clearance_cost=2.0))
    ys_hug = densify(hug.waypoints)[:, 1]
    ys_mid = densify(mid.waypoints)[:, 1]
    inside = slice(len(ys_mid) // 3, 2 * len(ys_mid) // 3)
    assert abs(np.median(ys_mid[inside]) - 2.5) < 0.1  # the corridor's centre line
    assert abs(np.median(ys_hug[len(ys_hug) // 3: 2 * len(ys_hug) // 3]) - 2.5) > 0.1
    plan_path(occ, start, goal)


@pytest.mark.parametrize("backend", ["numba", "mcp", "pyastar2d"])
def test_backends_plan_valid_paths(backend: str) -> None:
    if backend == "mcp":
        pytest.importorskip("skimage")
    if backend == "pyastar2d":
        pytest.importorskip("pyastar2d")
    occ = wall_with_gap(1.0)
    cfg = PlannerConfig(backend=backend)
    path = plan_path(occ, (1.0, 1.0), (5.0, 4.0), cfg)
    ours = plan_path(occ, (1.0, 1.0), (5.0, 4.0), PlannerConfig())
    assert clearance(occ, densify(path.waypoints)).min() >= cfg.inflation - RES / 2 - 1e-9
    if backend == "pyastar2d":  # optimal for its own metric only: never cheaper under ours
        assert path.cost >= ours.cost - 1e-9
    else:
        assert path.cost == pytest.approx(ours.cost, rel=1e-9)


def test_polygon_centroid_is_the_area_centroid() -> None:
    from capnav.planning.goal import polygon_centroid

    # A square with extra vertices crowded on one side: the vertex mean is pulled, the centroid not.
    sq = np.array([[0, 0], [2, 0], [2, 0.5], [2, 1], [2, 1.5], [2, 2], [0, 2]], dtype=float)
    assert polygon_centroid(sq) == pytest.approx([1.0, 1.0])
    assert polygon_centroid(sq[::-1]) == pytest.approx([1.0, 1.0])  # either orientation
    assert polygon_centroid(np.array([[1.0, 2.0]])) == pytest.approx([1.0, 2.0])
    assert polygon_centroid(np.array([[0.0, 0.0], [2.0, 2.0]])) == pytest.approx([1.0, 1.0])
