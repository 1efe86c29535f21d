"""Grid search backends by name: our numba A* and, for comparison, three reference libraries.

All take the same float64 weight grid (``inf`` = blocked, >= 1 elsewhere) and return the cell path
and its cost under one rule (``search.edge cost = step * mean weight``), so they are comparable.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, pip_hint
from capnav.core.registry import Registry
from capnav.planning.search import astar

Cell = tuple[int, int]


class GridSearch(Protocol):
    def __call__(self, weights: NDArray[np.floating], start: Cell, goal: Cell) -> tuple[NDArray[np.intp], float]:
        """Cells (K, 2) from start to goal (empty when unreachable) and the path cost in cells."""
        ...


BACKENDS: Registry[GridSearch] = Registry("grid search")


def path_cost(weights: NDArray[np.floating], cells: NDArray[np.integer]) -> float:
    """Cost of a cell path under the shared edge rule (step length times mean weight)."""
    if len(cells) < 2:
        return 0.0 if len(cells) else float("inf")
    c = np.asarray(cells)
    w = weights[c[:, 0], c[:, 1]]
    step = np.where(np.abs(np.diff(c, axis=0)).sum(axis=1) == 2, np.sqrt(2.0), 1.0)
    return float(np.sum(step * 0.5 * (w[:-1] + w[1:])))


@BACKENDS.register("numba")
def _numba_factory() -> GridSearch:
    return astar


@BACKENDS.register("mcp")
def _mcp_factory() -> GridSearch:
    """scikit-image's minimum-cost-path (Dijkstra, same geometric edge rule); ``bench`` extra."""
    try:
        from skimage.graph import MCP_Geometric
    except ImportError:
        raise InputError(f"backend 'mcp' needs scikit-image: {pip_hint('capnav[bench]')}") from None

    def search(weights: NDArray[np.floating], start: Cell, goal: Cell) -> tuple[NDArray[np.intp], float]:
        costs = np.where(np.isfinite(weights), weights, -1.0)  # negative = impassable for MCP
        mcp = MCP_Geometric(costs, fully_connected=True)
        cum, _ = mcp.find_costs([start], [goal])
        if not np.isfinite(cum[goal]):
            return np.empty((0, 2), np.intp), float("inf")
        return np.asarray(mcp.traceback(goal), dtype=np.intp), float(cum[goal])

    return search


@BACKENDS.register("pyastar2d")
def _pyastar_factory() -> GridSearch:
    """pyastar2d's C++ A* (``bench`` extra). It prices a diagonal step like a straight one, so its
    path is optimal for that metric only; the cost returned here is its path under ours."""
    try:
        import pyastar2d
    except ImportError:
        raise InputError(f"backend 'pyastar2d' needs pyastar2d: {pip_hint('capnav[bench]')}") from None

    def search(weights: NDArray[np.floating], start: Cell, goal: Cell) -> tuple[NDArray[np.intp], float]:
        # its native float32 (no copy of a float32 costmap: the call is timed as the library's own)
        path = pyastar2d.astar_path(np.asarray(weights, np.float32), start, goal, allow_diagonal=True)
        if path is None:
            return np.empty((0, 2), np.intp), float("inf")
        cells = np.asarray(path, dtype=np.intp)
        return cells, path_cost(weights, cells)

    return search


@BACKENDS.register("tcod")
def _tcod_factory() -> GridSearch:
    """libtcod's C A* (python-tcod, ``bench`` extra) with diagonal steps costing sqrt(2): the
    octile metric, so on uniform grids its paths are optimal for ours. It prices a step by the
    weight of the cell entered (not the mean of both cells), so on graded grids its path is
    optimal for that rule only; the cost returned here is its path under ours."""
    try:
        import tcod.path
    except ImportError:
        raise InputError(f"backend 'tcod' needs python-tcod: {pip_hint('capnav[bench]')}") from None

    def search(weights: NDArray[np.floating], start: Cell, goal: Cell) -> tuple[NDArray[np.intp], float]:
        cost = np.where(np.isfinite(weights), weights, 0.0).astype(np.float32)  # 0 = blocked for tcod
        steps = tcod.path.AStar(cost, diagonal=float(np.sqrt(2.0))).get_path(start[0], start[1], goal[0], goal[1])
        if not steps and tuple(start) != tuple(goal):
            return np.empty((0, 2), np.intp), float("inf")
        cells = np.asarray([tuple(start), *steps], dtype=np.intp)
        return cells, path_cost(weights, cells)

    return search
