"""Top-down occupancy from the voxel map (section 3.4's "derived occupancy map").

A cell is OCCUPIED when a voxel whose centre lies in the obstacle height band is above it, FREE
when only floor voxels were observed there, UNKNOWN otherwise. Inflation by the robot radius is
``OccupancyGrid.inflated``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.mapping.voxel_map import VoxelMap


@dataclass(frozen=True)
class OccupancyConfig:
    """``resolution`` 0.05 m; obstacles between ``obstacle_min`` (0.1 m: above floor noise and
    thresholds) and ``obstacle_max`` (1.8 m: a robot passes under nothing lower, the ceiling is
    above); floor voxels have centres below ``floor_max``; voxels with accumulated weight below
    ``min_weight`` are ignored (single far returns)."""

    resolution: float = 0.05
    obstacle_min: float = 0.1
    obstacle_max: float = 1.8
    floor_max: float = 0.1
    min_weight: float = 0.02
    margin: float = 0.5

    def __post_init__(self) -> None:
        if self.resolution <= 0 or self.obstacle_max <= self.obstacle_min:
            raise InputError("occupancy resolution must be > 0 and obstacle_max > obstacle_min")


def occupancy_from_voxels(voxels: VoxelMap, config: OccupancyConfig | None = None,
                          spec: GridSpec | None = None, cover: NDArray[np.floating] | None = None) -> OccupancyGrid:
    """Build the FREE / OCCUPIED / UNKNOWN grid; ``spec`` defaults to the voxels' extent + margin,
    grown to hold the (N, 2) points ``cover`` too (the cameras: a camera looking ahead never sees
    the floor it stands on, and a one-frame map would otherwise put its own start off the map)."""
    cfg = config or OccupancyConfig()
    c = voxels.centers()
    keep = voxels.weights >= cfg.min_weight
    c = c[keep]
    if spec is None:
        if len(c) == 0:
            spec = GridSpec(0.0, 0.0, cfg.resolution, 1, 1)
        else:
            # Grid lines on voxel faces (centre - s/2), never through voxel centres: a centre exactly
            # on a cell boundary falls either way under round-off and leaves stripes of UNKNOWN cells.
            h = voxels.resolution / 2.0
            lo, hi = c[:, :2].min(axis=0) - h, c[:, :2].max(axis=0) + h
            if cover is not None and len(cover):
                # grown by whole voxels, so that the grid lines stay on voxel faces
                q = np.asarray(cover, dtype=np.float64)[:, :2]
                r = voxels.resolution
                lo = lo - np.ceil(np.maximum(lo - q.min(axis=0), 0.0) / r) * r
                hi = hi + np.ceil(np.maximum(q.max(axis=0) - hi, 0.0) / r) * r
            spec = GridSpec.covering(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]), cfg.resolution,
                                     cfg.margin)
    cells = np.full((spec.rows, spec.cols), UNKNOWN, dtype=np.uint8)
    half = voxels.resolution / 2.0
    # A voxel covers a square of side s; mark every cell it overlaps (matters when s > resolution).
    n_sub = max(1, int(np.ceil(voxels.resolution / spec.resolution)))
    offs = (np.arange(n_sub) + 0.5) / n_sub * voxels.resolution - half
    floor = c[:, 2] < cfg.floor_max
    obst = (c[:, 2] >= cfg.obstacle_min) & (c[:, 2] <= cfg.obstacle_max)
    for sel, value in ((floor, FREE), (obst, OCCUPIED)):
        xy = c[sel, :2]
        for dx in offs:
            for dy in offs:
                rc = spec.to_cell(xy + np.array([dx, dy]))
                ok = spec.inside(rc)
                cells[rc[ok, 0], rc[ok, 1]] = value
    return OccupancyGrid(spec, cells)
