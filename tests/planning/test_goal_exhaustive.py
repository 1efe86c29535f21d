"""The goal pose the search stops at is the one a whole-grid Dijkstra picks: the cheapest cell of
the goal rule's first tier that sees the object, on rooms with furniture and a door, from many
starts; the per-object setup a costmap keeps gives the same pose as a fresh one, and is dropped
when a contact marks the map."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
from capnav.planning import PlannerConfig, build_costmap, select_goal
from capnav.planning.costmap import locate_start, mark_blocked
from capnav.planning.goal import _around, prepare_goal
from capnav.planning.search import cost_field
from capnav.planning.sight import HeightColumns

RES = 0.05


def furnished(seed: int) -> tuple[OccupancyGrid, HeightColumns, list[tuple[np.ndarray, tuple[float, float]]]]:
    """A 6 x 4 m flat: outer walls, a wall at x = 3 with a 0.9 m door, and random furniture of random
    heights (the objects, as footprints with their height ranges)."""
    rng = np.random.default_rng(seed)
    w, h = 6.0, 4.0
    spec = GridSpec(0.0, 0.0, RES, round(h / RES), round(w / RES))
    door = float(rng.uniform(0.6, 2.6))
    parts = [(0, 0, w, 0.1, 0.0, 2.6), (0, h - 0.1, w, h, 0.0, 2.6), (0, 0, 0.1, h, 0.0, 2.6),
             (w - 0.1, 0, w, h, 0.0, 2.6), (2.95, 0, 3.05, door, 0.0, 2.6), (2.95, door + 0.9, 3.05, h, 0.0, 2.6)]
    objects = []
    for _ in range(9):
        x0, y0 = rng.uniform([0.3, 0.3], [5.2, 3.2])
        x1, y1 = x0 + rng.uniform(0.2, 0.7), y0 + rng.uniform(0.2, 0.6)
        z0 = float(rng.choice([0.0, 0.0, 0.7]))
        z1 = z0 + float(rng.uniform(0.3, 1.4))
        parts.append((x0, y0, x1, y1, z0, z1))
        objects.append((np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), (z0, z1)))
    pts = []
    for x0, y0, x1, y1, z0, z1 in parts:
        xs, ys = np.arange(x0 + RES / 2, x1, RES), np.arange(y0 + RES / 2, y1, RES)
        zs = np.arange(max(z0, 0.0) + RES / 2, z1, RES)
        pts.append(np.stack(np.meshgrid(xs, ys, zs, indexing="ij"), axis=-1).reshape(-1, 3))
    cols = HeightColumns.from_points(spec, np.concatenate(pts))
    cells = np.where(cols.masks != 0, OCCUPIED, FREE).astype(np.uint8)
    return OccupancyGrid(spec, cells), cols, objects


def exhaustive(cm, fp, z, start, cfg) -> tuple[float, list[tuple[int, int]]] | None:  # type: ignore[no-untyped-def]
    """The cost of the cheapest cell of the first tier (within reach less the margin, seen free
    floor, in the object's room, traversable) that sees the object, from a Dijkstra over the whole
    grid, and every cell at that cost; None when no such cell is reachable."""
    s, _ = locate_start(cm, start, cfg)
    field, _ = cost_field(cm.weights, s)
    ar = _around(cm, fp, cfg, cm.columns, z, None)
    cells = ar.cells()
    ok = ar.seen & ar.in_room & (ar.dist <= cfg.reach - cfg.goal_margin)
    cost = field[cells[:, 0], cells[:, 1]]
    order = [i for i in np.argsort(cost, kind="stable") if ok[i] and np.isfinite(cost[i])]
    seen = [i for i in order if ar.sight is not None and ar.sight(cells[i:i + 1])[0]]
    if not seen:
        return None
    best = float(cost[seen[0]])
    ties = [(int(cells[i, 0]), int(cells[i, 1])) for i in seen if cost[i] <= best * (1 + 1e-9)]
    return best * cm.spec.resolution, ties


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_search_stops_at_the_cell_a_whole_grid_dijkstra_picks(seed: int) -> None:
    occ, cols, objects = furnished(seed)
    cfg = PlannerConfig()
    cm = build_costmap(occ, cfg, cols)
    rng = np.random.default_rng(100 + seed)
    free = np.argwhere(np.isfinite(cm.weights))
    compared = 0
    for fp, z in objects:
        for r, c in free[rng.choice(len(free), size=4, replace=False)]:
            start = occ.spec.to_world(np.array([r, c]))
            ref = exhaustive(cm, fp, z, start, cfg)
            got = select_goal(occ, fp, start, cfg, cm, z_range=z)
            if ref is None:  # a relaxed tier: the search ran to the end, as the reference did
                assert got.in_sight is not True or got.in_room is not True
                continue
            cost, ties = ref
            assert got.cell in ties and got.path_cost == pytest.approx(cost, rel=1e-8)
            compared += 1
            fresh = select_goal(occ, fp, start, cfg, build_costmap(occ, cfg, cols), z_range=z)
            assert got.to_dict() == fresh.to_dict()  # the costmap's kept setup answers as a fresh one
    assert compared >= 20


def test_a_contact_mark_drops_the_kept_setup() -> None:
    occ, cols, objects = furnished(3)
    cfg = PlannerConfig()
    cm = build_costmap(occ, cfg, cols)
    fp, z = objects[0]
    start = occ.spec.to_world(np.argwhere(np.isfinite(cm.weights))[0])
    first = select_goal(occ, fp, start, cfg, cm, z_range=z)
    assert cm.cache["goal_around"]
    mark_blocked(cm, first.xy, 0.1, cfg)  # the goal found blocked: the cells around it are occupied now
    assert "goal_around" not in cm.cache
    again = select_goal(occ, fp, start, cfg, cm, z_range=z)
    uncached = select_goal(occ, fp, start, cfg, cm, z_range=z, allowed=np.ones(cm.weights.shape, bool))
    assert again.to_dict() == uncached.to_dict() and again.cell != first.cell


@pytest.mark.parametrize("seed", [0, 1, 2, 4, 5])
def test_the_goal_field_gives_the_cell_a_whole_grid_dijkstra_picks(seed: int) -> None:
    # With each object's goal field made (the cells that pass the whole rule, and a lower bound
    # of the cost to them from every cell), the search from a robot position no search started
    # from heads for them: the same cost as the exhaustive reference, a cell of its ties, and the
    # pose the search without a field gives (or one of the same cost, when two cells tie).
    occ, cols, objects = furnished(seed)
    cfg = PlannerConfig()
    cm = build_costmap(occ, cfg, cols)
    plain = build_costmap(occ, cfg, cols)
    plain.cache["no_fields"] = True
    made = sum(prepare_goal(occ, fp, cm, cfg, z_range=z) for fp, z in objects)
    assert made >= 6
    rng = np.random.default_rng(200 + seed)
    free = np.argwhere(np.isfinite(cm.weights))
    compared = same = 0
    for fp, z in objects:
        for r, c in free[rng.choice(len(free), size=6, replace=False)]:
            start = occ.spec.to_world(np.array([r, c]))
            got = select_goal(occ, fp, start, cfg, cm, z_range=z)
            without = select_goal(occ, fp, start, cfg, plain, z_range=z)
            ref = exhaustive(cm, fp, z, start, cfg)
            if ref is None:  # a relaxed tier: no field applies, the search runs as without one
                assert got.to_dict() == without.to_dict()
                continue
            cost, ties = ref
            assert got.cell in ties and got.path_cost == pytest.approx(cost, rel=1e-8)
            assert got.reason == without.reason and got.path_cost == pytest.approx(without.path_cost, rel=1e-8)
            compared += 1
            same += got.to_dict() == without.to_dict()
    assert compared >= 20 and same >= compared - 3


def test_a_goal_field_is_made_on_the_second_search_and_dropped_by_a_contact_mark() -> None:
    occ, cols, objects = furnished(6)
    cfg = PlannerConfig()
    cm = build_costmap(occ, cfg, cols)
    fp, z = objects[0]
    free = np.argwhere(np.isfinite(cm.weights))
    starts = [occ.spec.to_world(free[i]) for i in (0, len(free) // 2, len(free) - 1)]
    select_goal(occ, fp, starts[0], cfg, cm, z_range=z)
    assert not cm.cache.get("goal_field")  # a one-shot query pays for no field
    select_goal(occ, fp, starts[1], cfg, cm, z_range=z)
    assert len(cm.cache["goal_field"]) == 1
    first = select_goal(occ, fp, starts[2], cfg, cm, z_range=z)
    mark_blocked(cm, first.xy, 0.1, cfg)
    assert "goal_field" not in cm.cache
    again = select_goal(occ, fp, starts[2], cfg, cm, z_range=z)
    uncached = select_goal(occ, fp, starts[2], cfg, cm, z_range=z, allowed=np.ones(cm.weights.shape, bool))
    assert again.to_dict() == uncached.to_dict()


def test_the_field_search_matches_the_octile_search_on_weighted_grids() -> None:
    # NearestSearch with a goal field (rounded down, so it may be inconsistent by one unit: cells
    # are opened again) settles a target of the same cost as the search towards the box, on
    # random weights where the field's walk bound is far below the cost.
    from capnav.planning.nearest import NO_PATH, NearestSearch, goal_field

    rng = np.random.default_rng(7)
    for _ in range(20):
        w = rng.uniform(1.0, 4.0, (40, 50)).astype(np.float32)
        w[rng.random(w.shape) < 0.2] = np.inf
        box = (15, 20, 24, 31)
        target = np.zeros((10, 12), bool)
        target[rng.random(target.shape) < 0.15] = True
        cells = np.argwhere(target) + np.array([15, 20])
        w[cells[:, 0], cells[:, 1]] = np.minimum(w[cells[:, 0], cells[:, 1]], 4.0)
        hq = goal_field(w, cells, 1.0)
        for s in np.argwhere(np.isfinite(w))[rng.choice(int(np.isfinite(w).sum()), 5, replace=False)]:
            ref = NearestSearch(w, (int(s[0]), int(s[1])), target, box, 1.0).next()
            got = NearestSearch(w, (int(s[0]), int(s[1])), target, box, 1.0, hq).next()
            if ref is None:
                assert got is None or hq[s[0] * 50 + s[1]] == NO_PATH
                continue
            assert got is not None and got[1] == pytest.approx(ref[1], rel=1e-8)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_goal_field_is_the_dijkstra_cost_rounded_down(dtype: type) -> None:
    # The bucket walk gives every cell's cost to the nearest source within one unit below the
    # heap Dijkstra's (float32 weights: each move is the float the search adds), never above it:
    # an admissible heuristic, and NO_PATH exactly where no source is reachable.
    from capnav.planning.nearest import FIELD_UNIT, NO_PATH, NearestSearch, goal_field

    rng = np.random.default_rng(3)
    for _ in range(10):
        w = rng.uniform(1.0, 5.0, (60, 70)).astype(dtype)
        w[rng.random(w.shape) < 0.25] = np.inf
        src = np.argwhere(np.isfinite(w))[rng.choice(int(np.isfinite(w).sum()), 3, replace=False)]
        hq = goal_field(w, src, float(w[np.isfinite(w)].min()))
        ref = NearestSearch(w, src, np.zeros((1, 1), bool), (0, 0, 0, 0), min_weight=0.0).finish().ravel()
        ok = np.isfinite(ref)
        np.testing.assert_array_equal(hq == NO_PATH, ~ok)
        gap = ref[ok] - hq[ok] * FIELD_UNIT
        assert gap.min() >= 0.0 and gap.max() < FIELD_UNIT
