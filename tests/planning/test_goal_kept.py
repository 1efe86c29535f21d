"""A goal pose kept per (object, start cell) on a costmap is the pose a fresh search chooses:
from many starts in rooms with a door, furniture and a shut room, asked once (the search, or the
whole-grid one when nothing within reach is reachable) and again (the kept pose, also from
another point of the same cell), against the path that keeps nothing (``allowed`` given); a
caller changing the returned pose does not change the kept one, and a contact mark drops the
kept poses."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
from capnav.planning import PlannerConfig, build_costmap, select_goal
from capnav.planning.costmap import mark_blocked

RES = 0.05


def flat(seed: int) -> tuple[OccupancyGrid, list[tuple[np.ndarray, tuple[float, float]]]]:
    """An 8 x 5 m flat: outer walls, a wall at x = 4 with a door, seeded boxes on the floor and a shut room."""
    rng = np.random.default_rng(seed)
    spec = GridSpec(0.0, 0.0, RES, round(5.0 / RES), round(8.0 / RES))
    cells = np.full((spec.rows, spec.cols), FREE, np.uint8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = OCCUPIED
    c = round(4.0 / RES)
    cells[:, c - 1:c + 1] = OCCUPIED
    r = int(rng.integers(10, spec.rows - 30))
    cells[r:r + 18, c - 1:c + 1] = FREE  # a 0.9 m door
    objects = []
    for _ in range(8):
        x0, y0 = rng.uniform([0.4, 0.4], [7.0, 4.0])
        x1, y1 = x0 + rng.uniform(0.2, 0.7), y0 + rng.uniform(0.2, 0.6)
        (r0, c0), (r1, c1) = spec.to_cell(np.array([x0, y0])), spec.to_cell(np.array([x1, y1]))
        cells[r0:r1 + 1, c0:c1 + 1] = OCCUPIED
        objects.append((np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), (0.0, float(rng.uniform(0.4, 1.5)))))
    # A shut room along the bottom wall (no door): from outside it nothing within reach of its shelf
    # is reachable (the last tier).
    cells[2:40, 120:124] = OCCUPIED
    cells[36:40, 2:124] = OCCUPIED
    objects.append((np.array([[1.0, 0.4], [1.6, 0.4], [1.6, 0.8], [1.0, 0.8]]), (0.0, 1.8)))
    return OccupancyGrid(spec, cells), objects


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_kept_pose_is_the_pose_a_fresh_search_chooses(seed: int) -> None:
    occ, objects = flat(seed)
    cfg = PlannerConfig()
    cm = build_costmap(occ, cfg)
    everywhere = np.ones(cm.weights.shape, bool)  # the uncached path: nothing kept is read or written
    rng = np.random.default_rng(50 + seed)
    free = np.argwhere(np.isfinite(cm.weights))
    tiers = set()
    for fp, z in objects:
        for r, c in free[rng.choice(len(free), size=5, replace=False)]:
            start = occ.spec.to_world(np.array([r, c]))
            fresh = select_goal(occ, fp, start, cfg, cm, z_range=z, allowed=everywhere)
            first = select_goal(occ, fp, start, cfg, cm, z_range=z)  # searched, then kept
            again = select_goal(occ, fp, start + 0.3 * RES, cfg, cm, z_range=z)  # same cell: the kept pose
            assert first.to_dict() == fresh.to_dict() == again.to_dict()
            tiers.add((fresh.reached_within_reach, fresh.in_sight, fresh.in_room))
    assert len(cm.cache["goal_pose"]) >= 30
    assert (True, True, True) in tiers and (False, None, None) in tiers  # the first tier and the last


def test_a_changed_pose_leaves_the_kept_one_and_a_contact_mark_drops_them() -> None:
    occ, objects = flat(3)
    cfg = PlannerConfig()
    cm = build_costmap(occ, cfg)
    fp, z = objects[0]
    start = occ.spec.to_world(np.argwhere(np.isfinite(cm.weights))[0])
    first = select_goal(occ, fp, start, cfg, cm, z_range=z)
    xy = first.xy.copy()
    first.xy[:] = -1.0  # a caller moving its copy
    np.testing.assert_array_equal(select_goal(occ, fp, start, cfg, cm, z_range=z).xy, xy)
    mark_blocked(cm, xy, 0.1, cfg)  # the goal found blocked
    assert "goal_pose" not in cm.cache
    again = select_goal(occ, fp, start, cfg, cm, z_range=z)
    uncached = select_goal(occ, fp, start, cfg, cm, z_range=z, allowed=np.ones(cm.weights.shape, bool))
    assert again.to_dict() == uncached.to_dict() and again.cell != first.cell
