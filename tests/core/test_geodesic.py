"""The bucket-queue walking distance gives the very floats of a heap-ordered Dijkstra (the routine
it replaced, kept here in plain Python as the reference), with and without a distance limit, and
walking distances to objects keep their order where it differs from the straight line. Walking
distances to objects are exact (a + b sqrt 2 from the step counts): the reference counts steps
too, and an object's walk field read at a robot's cell gives the float of the walk from the robot."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest

from capnav.core.geodesic import box_minima, grid_geodesic
from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
from capnav.language.rooms import box_cells, box_min
from capnav.retrieval.spatial import RING, FloorDistances

_MOVES = [(-1, -1, math.sqrt(2)), (-1, 0, 1.0), (-1, 1, math.sqrt(2)), (0, -1, 1.0), (0, 1, 1.0),
          (1, -1, math.sqrt(2)), (1, 0, 1.0), (1, 1, math.sqrt(2))]


def heap_dijkstra(domain: np.ndarray, seeds: np.ndarray, limit: float, exact: bool = False) -> np.ndarray:
    """The replaced routine: a binary heap, no closed set, cells past ``limit`` not expanded.
    ``exact``: each distance is a + b sqrt 2 from its path's counts of straight (a) and diagonal
    (b) steps, not summed step by step (the walking distances to objects)."""
    rows, cols = domain.shape
    dist = np.full((rows, cols), np.inf)
    counts = np.zeros((rows, cols, 2), np.int64)
    heap: list[tuple[float, int, int]] = []
    for r, c in seeds:
        dist[r, c] = 0.0
        heap.append((0.0, int(r), int(c)))
    heapq.heapify(heap)
    while heap:
        d, r, c = heapq.heappop(heap)
        if d > dist[r, c] or d > limit:
            continue
        for dr, dc, w in _MOVES:
            rr, cc = r + dr, c + dc
            if not (0 <= rr < rows and 0 <= cc < cols and domain[rr, cc]):
                continue
            a, b = counts[r, c] + ((0, 1) if dr and dc else (1, 0))
            nd = float(a) + float(b) * math.sqrt(2) if exact else d + w
            if nd < dist[rr, cc]:
                dist[rr, cc] = nd
                counts[rr, cc] = a, b
                heapq.heappush(heap, (nd, rr, cc))
    return dist


def rooms_with_doors(rng: np.random.Generator, rows: int, cols: int) -> np.ndarray:
    dom = rng.random((rows, cols)) > 0.12  # scattered clutter
    for c in rng.choice(np.arange(3, cols - 3), size=2, replace=False):
        dom[:, c] = False
        r = int(rng.integers(0, rows - 3))
        dom[r:r + 3, c] = True
    r = int(rng.integers(3, rows - 3))
    dom[r, : cols // 2] = False  # a closed-off pocket may leave cells unreachable
    return dom


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
@pytest.mark.parametrize("limit", [math.inf, 7.5])
def test_same_floats_as_the_heap_dijkstra(seed: int, limit: float) -> None:
    rng = np.random.default_rng(seed)
    dom = rooms_with_doors(rng, 23, 31)
    free = np.argwhere(dom)
    seeds = free[rng.choice(len(free), size=1 + seed, replace=False)].astype(np.int64)
    got = grid_geodesic(dom, seeds, limit)
    ref = heap_dijkstra(dom, seeds, limit)
    assert np.isinf(ref).any()  # walls and the pocket leave unreachable cells (limit or not)
    np.testing.assert_array_equal(got, ref)


def test_a_seed_outside_the_domain_still_starts_the_walk_and_duplicates_are_harmless() -> None:
    dom = np.ones((6, 7), dtype=bool)
    dom[2, 3] = False
    seeds = np.array([[2, 3], [2, 3], [0, 0]], dtype=np.int64)
    np.testing.assert_array_equal(grid_geodesic(dom, seeds, math.inf), heap_dijkstra(dom, seeds, math.inf))


def test_box_minima_match_the_per_box_loop() -> None:
    rng = np.random.default_rng(5)
    spec = GridSpec(0.0, 0.0, 0.1, 40, 50)
    dom = rooms_with_doors(rng, 40, 50)
    field = grid_geodesic(dom, np.array([[5, 5]], np.int64), math.inf) * spec.resolution
    los = rng.uniform([-0.5, -0.5], [4.5, 3.5], (60, 2))
    his = los + rng.uniform(0.05, 1.0, (60, 2))
    boxes = np.array([box_cells(spec, lo, hi) for lo, hi in zip(los, his, strict=True)], np.int64)
    grown = np.array([box_cells(spec, lo - RING, hi + RING) for lo, hi in zip(los, his, strict=True)], np.int64)
    got = box_minima(field, boxes, grown, RING)
    ref = np.array([box_min(field, spec, lo, hi, RING) for lo, hi in zip(los, his, strict=True)])
    np.testing.assert_array_equal(got, ref)
    assert 10 < np.isfinite(ref).sum() < len(ref)  # reached boxes and boxes no walk reaches


def test_walking_order_differs_from_the_straight_line_and_matches_the_reference() -> None:
    # A 6 x 4 m room split by a wall at x = 3 with its door at the far north end: object 0 is 1 m
    # from the robot through the wall, object 1 is 2.5 m away on the robot's own side.
    spec = GridSpec(0.0, 0.0, 0.1, 40, 60)
    cells = np.full((40, 60), FREE, np.uint8)
    cells[:34, 29:31] = OCCUPIED
    occ = OccupancyGrid(spec, cells)
    los = np.array([[3.4, 0.8], [0.3, 2.2]])
    his = los + 0.4
    robot = (2.4, 1.0)
    floor = FloorDistances(occ, los, his)
    d = floor.from_point(robot)
    line = np.hypot(*((los + his) / 2 - robot).T)
    assert np.argmin(line) == 0 and np.argmin(d) == 1
    rc = spec.to_cell(np.asarray(robot))
    ref_field = heap_dijkstra(floor.domain, np.array([rc], np.int64), math.inf, exact=True) * spec.resolution
    ref = np.array([box_min(ref_field, spec, lo, hi) for lo, hi in zip(los, his, strict=True)])
    np.testing.assert_array_equal(d, ref)
    assert floor.from_point(robot) is d  # cached per source cell
    np.testing.assert_array_equal(floor.from_objects(np.array([1])), floor.from_objects(np.array([1])))


def test_the_cache_keeps_the_most_recently_used_sources() -> None:
    spec = GridSpec(0.0, 0.0, 0.1, 20, 20)
    occ = OccupancyGrid(spec, np.full((20, 20), FREE, np.uint8))
    floor = FloorDistances(occ, np.array([[0.5, 0.5]]), np.array([[0.7, 0.7]]), cache_size=2)
    a = floor.from_point((1.0, 1.0))
    floor.from_point((1.5, 1.5))
    assert floor.from_point((1.0, 1.0)) is a  # used again: now the most recent
    floor.from_point((0.2, 1.8))  # evicts (1.5, 1.5), the least recently used
    assert floor.from_point((1.0, 1.0)) is a


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_floor_distances_give_the_floats_of_the_heap_dijkstra_and_the_per_box_loop(seed: int) -> None:
    # The fused kernel (walk on the padded grid made once per map, minima over the boxes without the
    # whole field) against the replaced routine, from many sources, with boxes partly off the grid
    # and boxes in the closed-off pocket (measured at their grown ring, or not at all).
    rng = np.random.default_rng(10 + seed)
    spec = GridSpec(0.0, 0.0, 0.1, 30, 45)
    dom = rooms_with_doors(rng, 30, 45)
    dom[18:27, 30:39] = False  # a closed room: its walls, and inside them
    dom[19:26, 31:38] = True
    occ = OccupancyGrid(spec, np.where(dom, FREE, OCCUPIED).astype(np.uint8))
    los = rng.uniform([-0.4, -0.4], [4.4, 2.9], (40, 2))
    his = los + rng.uniform(0.05, 0.6, (40, 2))
    inner = spec.to_world(np.array([[20, 32], [21, 34]]))  # in the closed room, within RING of its walls
    los[-3:] = [inner.min(axis=0), spec.to_world(np.array([22, 35])), [-3.0, -3.0]]  # the last: off the grid
    his[-3:] = [inner.max(axis=0), spec.to_world(np.array([24, 36])), [-2.0, -2.0]]
    floor = FloorDistances(occ, los, his, cache_size=1)
    free = np.argwhere(floor.domain)
    finite, ring = 0, 0
    for r, c in free[rng.choice(len(free), size=6, replace=False)]:
        xy = spec.to_world(np.array([r, c]))
        got = floor.from_point((float(xy[0]), float(xy[1])))
        field = heap_dijkstra(floor.domain, np.array([spec.to_cell(xy)], np.int64), math.inf,
                              exact=True) * spec.resolution
        ref = np.array([box_min(field, spec, lo, hi, RING) for lo, hi in zip(los, his, strict=True)])
        np.testing.assert_array_equal(got, ref)
        finite += int(np.isfinite(ref).sum())
        ring += int(np.isfinite(ref[-3]))
    pair = np.array([0, 3])
    field = heap_dijkstra(floor.domain, np.concatenate(
        [np.argwhere(np.ones((b[2] - b[0] + 1, b[3] - b[1] + 1), bool)) + b[:2]
         for b in (np.array(box_cells(spec, los[i], his[i])) for i in pair)
         if b[2] >= b[0] and b[3] >= b[1]]).astype(np.int64), math.inf, exact=True) * spec.resolution
    ref = np.array([box_min(field, spec, lo, hi, RING) for lo, hi in zip(los, his, strict=True)])
    np.testing.assert_array_equal(floor.from_objects(pair), ref)
    assert 0 < finite < 6 * len(los) and ring > 0  # unreached boxes, and one measured at its ring


def _closed_room_scene(rng: np.random.Generator, n: int
                       ) -> tuple[GridSpec, OccupancyGrid, np.ndarray, np.ndarray]:
    """Rooms with doors on a 3 x 4.5 m grid of 10 cm cells, one room walled shut, and ``n`` random
    object boxes (lows, highs), some poking off the grid."""
    spec = GridSpec(0.0, 0.0, 0.1, 30, 45)
    dom = rooms_with_doors(rng, 30, 45)
    dom[18:27, 30:39] = False
    dom[19:26, 31:38] = True
    occ = OccupancyGrid(spec, np.where(dom, FREE, OCCUPIED).astype(np.uint8))
    los = rng.uniform([-0.4, -0.4], [4.4, 2.9], (n, 2))
    return spec, occ, los, los + rng.uniform(0.05, 0.6, (n, 2))


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_a_walk_stopped_once_some_objects_are_measured_gives_their_floats(seed: int) -> None:
    # "The closest chair" measures the chairs only: the walk stops once each holds an expanded
    # cell. Their floats are the whole walk's; the others are nan, unless one of the asked is never
    # reached (in the closed room, or off the grid): then the walk ran on and every object has its
    # value. A later ask from the same cell fills in what the first left out.
    rng = np.random.default_rng(30 + seed)
    spec, occ, los, his = _closed_room_scene(rng, 40)
    los[-2:] = [spec.to_world(np.array([22, 35])), [-3.0, -3.0]]  # in the closed room; off the grid
    his[-2:] = [spec.to_world(np.array([24, 36])), [-2.0, -2.0]]
    whole = FloorDistances(occ, los, his, cache_size=0)
    free = np.argwhere(whole.domain)
    stopped = 0
    for k, (r, c) in enumerate(free[rng.choice(len(free), size=8, replace=False)]):
        xy = spec.to_world(np.array([r, c]))
        robot = (float(xy[0]), float(xy[1]))
        ref = whole.from_point(robot)
        among = rng.choice(len(los) - 2, size=1 + k % 4, replace=False)
        if k % 3 == 2:
            among = np.append(among, len(los) - 2 + k % 2)  # one no walk reaches (or only its ring)
        part = FloorDistances(occ, los, his)
        got = part.from_point(robot, among)
        np.testing.assert_array_equal(got[among], ref[among])
        rest = np.setdiff1d(np.arange(len(los)), among)
        if np.isnan(got).any():
            stopped += 1
            assert np.isfinite(ref[among]).all()  # stopped early only when every asked one was reached
        else:
            np.testing.assert_array_equal(got, ref)
        np.testing.assert_array_equal(part.from_point(robot, rest)[rest], ref[rest])  # filled in from here
        np.testing.assert_array_equal(part.from_point(robot), ref)
    assert stopped > 0


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_an_objects_walk_field_gives_the_floats_of_the_walk_from_the_robot(seed: int) -> None:
    # The field walked once from an object's cells, read at a robot's cell, is the float a walk
    # from the robot gives at that object (exact distances: the same from either end), so a
    # ranking from a robot position no walk started from is a lookup per object; with every field
    # made, with none (field_bytes 0) and with room for a few (the least recently used go), from
    # many robots, asking for some objects, one of them never reached (then the walk runs on).
    from capnav.core.geodesic import NO_WALK, walk_field, walk_value

    rng = np.random.default_rng(50 + seed)
    spec, occ, los, his = _closed_room_scene(rng, 30)
    los[-1], his[-1] = spec.to_world(np.array([22, 35])), spec.to_world(np.array([24, 36]))  # in the closed room
    plain = FloorDistances(occ, los, his, cache_size=0, field_bytes=0)
    full = FloorDistances(occ, los, his, cache_size=0)
    boxes = [box_cells(spec, lo, hi) for lo, hi in zip(los, his, strict=True)]
    assert full.prepare() == sum(b[2] >= b[0] and b[3] >= b[1] for b in boxes)  # an empty box has no field
    few = FloorDistances(occ, los, his, cache_size=0, field_bytes=3 * spec.rows * spec.cols * 4)
    free = np.argwhere(plain.domain)
    looked = 0
    for k, (r, c) in enumerate(free[rng.choice(len(free), size=12, replace=False)]):
        xy = spec.to_world(np.array([r, c]))
        robot = (float(xy[0]), float(xy[1]))
        among = rng.choice(len(los) - 1, size=1 + k % 5, replace=False)
        if k % 4 == 3:
            among = np.append(among, len(los) - 1)
        ref = plain.from_point(robot, among)
        for floor in (full, few, few):  # few: its second ranking may make the fields it lacks
            got = floor.from_point(robot, among)
            np.testing.assert_array_equal(got, ref)  # nan where ref is nan, the same floats elsewhere
        box = boxes[among[0]]
        f = full.field(int(among[0]), make=False)
        if f is None:
            continue
        if f[r * spec.cols + c] != NO_WALK:
            assert walk_value(int(f[r * spec.cols + c])) * spec.resolution == ref[among[0]]
            looked += 1
        seeds = np.argwhere(np.ones((box[2] - box[0] + 1, box[3] - box[1] + 1), bool)) + box[:2]
        np.testing.assert_array_equal(walk_field(full._base, spec.cols, seeds.astype(np.int64)), f)
    assert looked >= 4
    assert few._held <= 3 * spec.rows * spec.cols * 4 and len(few._fields) <= 3
