"""A* against a brute-force Dijkstra (scipy.sparse.csgraph) on random grids, and line of sight."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from capnav.planning.backends import BACKENDS, path_cost
from capnav.planning.search import astar, cost_field, line_clear, simplify


def random_weights(rng: np.random.Generator, rows: int, cols: int, p_block: float, p_heavy: float) -> np.ndarray:
    w = np.ones((rows, cols))
    w[rng.random((rows, cols)) < p_heavy] = 3.0
    w[rng.random((rows, cols)) < p_block] = np.inf
    return w


def dijkstra_costs(w: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """Every 8-neighbour edge priced step * mean weight, solved by scipy's Dijkstra."""
    rows, cols = w.shape
    idx = np.arange(rows * cols).reshape(rows, cols)
    src, dst, cost = [], [], []
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            if dr == dc == 0:
                continue
            a = idx[max(0, -dr):rows - max(0, dr), max(0, -dc):cols - max(0, dc)]
            b = idx[max(0, dr):rows - max(0, -dr) or None, max(0, dc):cols - max(0, -dc) or None]
            wa, wb = w.ravel()[a.ravel()], w.ravel()[b.ravel()]
            ok = np.isfinite(wa) & np.isfinite(wb)
            step = np.sqrt(2.0) if dr and dc else 1.0
            src.append(a.ravel()[ok])
            dst.append(b.ravel()[ok])
            cost.append(step * 0.5 * (wa[ok] + wb[ok]))
    g = coo_matrix((np.concatenate(cost), (np.concatenate(src), np.concatenate(dst))), shape=(w.size, w.size))
    d = dijkstra(g.tocsr(), indices=start[0] * cols + start[1])
    return d.reshape(rows, cols)


@pytest.mark.parametrize("seed", range(8))
def test_astar_cost_equals_brute_force_dijkstra(seed: int) -> None:
    rng = np.random.default_rng(seed)
    rows, cols = rng.integers(20, 60, size=2)
    w = random_weights(rng, int(rows), int(cols), p_block=0.25, p_heavy=0.2)
    free = np.argwhere(np.isfinite(w))
    truth = dijkstra_costs(w, tuple(free[0]))
    field, _ = cost_field(w, tuple(free[0]))
    np.testing.assert_allclose(field, truth, rtol=1e-9)
    for goal in free[rng.choice(len(free), size=10, replace=False)]:
        cells, cost = astar(w, tuple(free[0]), tuple(goal))
        expected = truth[tuple(goal)]
        if not np.isfinite(expected):
            assert len(cells) == 0 and cost == np.inf
            continue
        assert cost == pytest.approx(expected, rel=1e-8)
        # The path is real: 8-connected steps over traversable cells, priced at its cost.
        assert (np.abs(np.diff(cells, axis=0)).max(axis=1) == 1).all()
        assert np.isfinite(w[cells[:, 0], cells[:, 1]]).all()
        assert path_cost(w, cells) == pytest.approx(cost, rel=1e-9)
        assert tuple(cells[0]) == tuple(free[0]) and tuple(cells[-1]) == tuple(goal)


def test_open_grid_cost_is_octile_distance() -> None:
    w = np.ones((50, 80))
    _, cost = astar(w, (3, 4), (40, 70))
    dr, dc = 37, 66
    assert cost == pytest.approx((np.sqrt(2) - 1) * min(dr, dc) + max(dr, dc), rel=1e-9)


def test_unreachable_goal_gives_empty_path() -> None:
    w = np.ones((30, 30))
    w[:, 15] = np.inf
    cells, cost = astar(w, (5, 5), (5, 25))
    assert len(cells) == 0 and cost == np.inf


def test_mcp_backend_agrees() -> None:
    pytest.importorskip("skimage")
    rng = np.random.default_rng(3)
    w = random_weights(rng, 60, 60, 0.2, 0.1)
    w[0, 0] = w[-1, -1] = 1.0
    ours = BACKENDS.create("numba")(w, (0, 0), (59, 59))
    mcp = BACKENDS.create("mcp")(w, (0, 0), (59, 59))
    assert ours[1] == pytest.approx(mcp[1], rel=1e-9)


def test_line_clear_never_clips_a_corner() -> None:
    w = np.ones((5, 5))
    w[1, 2] = np.inf  # the segment (0,1)->(2,3) passes exactly through this cell's corner
    assert not line_clear(w, 0, 1, 2, 3, 1.0)
    assert line_clear(w, 0, 0, 4, 0, 1.0)
    w2 = np.ones((5, 5))
    w2[2, 2] = 3.0
    assert not line_clear(w2, 0, 0, 4, 4, 1.0)
    assert line_clear(w2, 0, 0, 4, 4, 3.0)


@pytest.mark.parametrize("seed", range(4))
def test_simplified_segments_are_clear(seed: int) -> None:
    rng = np.random.default_rng(seed)
    w = random_weights(rng, 80, 80, 0.15, 0.0)
    w[0, 0] = w[-1, -1] = 1.0
    cells, _ = astar(w, (0, 0), (79, 79))
    if len(cells) == 0:
        pytest.skip("random grid disconnected")
    keep = simplify(w, cells)
    assert keep[0] == 0 and keep[-1] == len(cells) - 1
    assert len(keep) < len(cells)
    for a, b in zip(cells[keep[:-1]], cells[keep[1:]], strict=True):
        # Either a clear straight segment, or one diagonal grid step of A* past a corner.
        one_step = np.abs(a - b).max() == 1
        assert one_step or line_clear(w, int(a[0]), int(a[1]), int(b[0]), int(b[1]), 1.0)


def test_kept_work_arrays_stay_correct_across_searches_and_raised_weights() -> None:
    """Searches on one grid reuse their arrays (no per-call scan or clearing): 300 searches (the
    one-byte stamps wrap twice) agree with a fresh grid, and a cell blocked in place between two
    searches is avoided by the next one."""
    rng = np.random.default_rng(5)
    w = random_weights(rng, 40, 50, p_block=0.2, p_heavy=0.2).astype(np.float32)
    free = np.argwhere(np.isfinite(w))
    for _ in range(300):
        a, b = free[rng.choice(len(free), size=2, replace=False)]
        _, cost = astar(w, tuple(a), tuple(b))
        _, fresh = astar(w.copy(), tuple(a), tuple(b))
        assert cost == fresh
    w = np.ones((20, 20), np.float32)
    cells, _ = astar(w, (10, 0), (10, 19))
    assert (cells[:, 0] == 10).all()  # straight along row 10
    w[3:18, 10] = np.inf  # raised in place, as mark_blocked does
    cells, cost = astar(w, (10, 0), (10, 19))
    assert np.isfinite(w[cells[:, 0], cells[:, 1]]).all() and cost > 19.5
    field, _ = cost_field(w, (10, 0))
    assert field[10, 19] == pytest.approx(cost) and np.isinf(field[10, 10])


def test_threads_search_one_grid_at_once() -> None:
    """Two threads on one weight grid: one uses the kept arrays, the other fresh ones."""
    from concurrent.futures import ThreadPoolExecutor

    rng = np.random.default_rng(6)
    w = random_weights(rng, 60, 60, p_block=0.2, p_heavy=0.2)
    free = np.argwhere(np.isfinite(w))
    pairs = [tuple(map(tuple, free[rng.choice(len(free), size=2, replace=False)])) for _ in range(40)]
    expected = [astar(w.copy(), a, b)[1] for a, b in pairs]
    with ThreadPoolExecutor(4) as ex:
        got = list(ex.map(lambda p: astar(w, p[0], p[1])[1], pairs))
    assert got == expected
