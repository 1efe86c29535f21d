"""Shortest navigable distance to a success region, for SPL.

SPL needs the geodesic distance from a subgoal's start to the *nearest* point of its success
region (all navigable cells within 1 m of any goal footprint). One multi-source Dijkstra from the
region over the 8-connected navigable grid gives that distance for every start at once, so the
field is computed once per (apartment, goal) and looked up per subgoal.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from capnav.core.errors import InputError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import GridSpec
from capnav.sim.success import SUCCESS_RADIUS_M


@dataclass
class DistanceField:
    """Geodesic distance (m) from every grid cell to a region; inf where unreachable."""

    spec: GridSpec
    dist: NDArray[np.float64]
    navigable: NDArray[np.bool_]

    def at(self, xy: Sequence[float] | NDArray[np.floating]) -> float:
        """Distance from a world point: its cell, or (if that is blocked, e.g. the agent stopped
        against an inflated obstacle) the nearest navigable cell plus the straight offset to it."""
        rc = self.spec.to_cell(np.asarray(xy, dtype=np.float64))
        r, c = int(rc[0]), int(rc[1])
        if 0 <= r < self.spec.rows and 0 <= c < self.spec.cols and self.navigable[r, c]:
            return float(self.dist[r, c])
        nav_rc = np.argwhere(self.navigable)
        if len(nav_rc) == 0:
            return float("inf")
        centres = self.spec.to_world(nav_rc)
        off = np.linalg.norm(centres - np.asarray(xy, dtype=np.float64)[None, :], axis=1)
        total = off + self.dist[nav_rc[:, 0], nav_rc[:, 1]]
        return float(total.min())


def region_mask(spec: GridSpec, navigable: NDArray[np.bool_], footprints: Sequence[NDArray[np.floating]],
                radius: float = SUCCESS_RADIUS_M) -> NDArray[np.bool_]:
    """Navigable cells whose centre lies within ``radius`` of any footprint."""
    rows, cols = np.nonzero(navigable)
    centres = spec.to_world(np.stack([rows, cols], axis=1))
    near = np.zeros(len(rows), dtype=bool)
    for f in footprints:
        near |= footprint_distance(centres, np.asarray(f)) <= radius
    mask = np.zeros_like(navigable, dtype=bool)
    mask[rows[near], cols[near]] = True
    return mask


def grid_graph(navigable: NDArray[np.bool_], resolution: float) -> tuple[coo_matrix, NDArray[np.intp]]:
    """Undirected 8-connected graph over navigable cells (diagonals only where both orthogonal
    neighbours are free, so paths never squeeze between two touching obstacles).
    Returns the sparse graph and the (rows, cols) -> node index map (-1 where blocked)."""
    nav = np.asarray(navigable, dtype=bool)
    index = np.full(nav.shape, -1, dtype=np.intp)
    index[nav] = np.arange(int(nav.sum()))
    src: list[NDArray[np.intp]] = []
    dst: list[NDArray[np.intp]] = []
    wts: list[NDArray[np.float64]] = []
    diag = resolution * np.sqrt(2.0)
    for dr, dc, w in ((0, 1, resolution), (1, 0, resolution), (1, 1, diag), (1, -1, diag)):
        a = nav[: nav.shape[0] - dr, max(0, -dc): nav.shape[1] - max(0, dc)]
        b = nav[dr:, max(0, dc): nav.shape[1] + min(0, dc)]
        ok = a & b
        if dr and dc:  # both orthogonal neighbours must be free too
            side1 = nav[dr:, max(0, -dc): nav.shape[1] - max(0, dc)]
            side2 = nav[: nav.shape[0] - dr, max(0, dc): nav.shape[1] + min(0, dc)]
            ok &= side1 & side2
        ia = index[: nav.shape[0] - dr, max(0, -dc): nav.shape[1] - max(0, dc)][ok]
        ib = index[dr:, max(0, dc): nav.shape[1] + min(0, dc)][ok]
        src.append(ia)
        dst.append(ib)
        wts.append(np.full(len(ia), w))
    n = int(nav.sum())
    graph = coo_matrix((np.concatenate(wts), (np.concatenate(src), np.concatenate(dst))), shape=(n, n))
    return graph, index


def distance_field(spec: GridSpec, navigable: NDArray[np.bool_], footprints: Sequence[NDArray[np.floating]],
                   radius: float = SUCCESS_RADIUS_M) -> DistanceField:
    """Geodesic distance from every navigable cell to the success region of ``footprints``."""
    nav = np.asarray(navigable, dtype=bool)
    if nav.shape != (spec.rows, spec.cols):
        raise InputError(f"navigable mask {nav.shape} does not match grid ({spec.rows}, {spec.cols})")
    return field_to(spec, nav, region_mask(spec, nav, footprints, radius))


def field_to(spec: GridSpec, navigable: NDArray[np.bool_], region: NDArray[np.bool_]) -> DistanceField:
    """Geodesic distance from every navigable cell to the cells of ``region`` (a mask of the grid)."""
    nav = np.asarray(navigable, dtype=bool)
    region = np.asarray(region, dtype=bool) & nav
    dist = np.full(nav.shape, np.inf)
    if region.any():
        graph, index = grid_graph(nav, spec.resolution)
        sources = index[region]
        d = dijkstra(graph, directed=False, indices=sources, min_only=True)
        dist[nav] = d
    return DistanceField(spec, dist, nav)



def walker(spec: GridSpec, navigable: NDArray[np.bool_], radius: float = SUCCESS_RADIUS_M
           ) -> Callable[[tuple[float, float], Any], float]:
    """``walk(xy, instance)``: metres along the navigable cells from ``xy`` to within ``radius`` of
    the instance's footprint (one distance field per instance, kept), for instructions that say
    "closest" the way a walker means it."""
    fields: dict[int, DistanceField] = {}

    def walk(xy: tuple[float, float], instance: Any) -> float:
        if instance.id not in fields:
            fields[instance.id] = distance_field(spec, navigable, [np.asarray(instance.footprint)], radius)
        return fields[instance.id].at(xy)

    return walk
