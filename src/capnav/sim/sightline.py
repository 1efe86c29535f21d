"""Ground-truth lines of sight on the floor plan: does a stopped agent see the object it reached?

The paper counts a subgoal as reached within 1 m of the object, wall or no wall: an agent 0.7 m
from a lamp but in the hallway behind the lamp's wall "succeeds". The strict rule adds that the
agent sees the object: a straight line from its stop point to some point of the object's footprint
that no wall, and no object taller than the line of sight's blocking height, crosses. Low furniture
(beds, tables, sofas) does not hide an object from a camera at 1.25 m, so it does not block.

This reads the simulator's truth (walls and object boxes): only the evaluation uses it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.grid import GridSpec
from capnav.sim.shapes import RectSet

WALL = -1
#: Objects at least this tall (m) hide what is behind them from the agent's camera (1.25 m).
BLOCK_HEIGHT_M = 1.0


def label_rects(spec: GridSpec, rects: RectSet, labels: Sequence[int], out: NDArray[np.int32]) -> None:
    """Write ``labels[k]`` into every cell whose centre lies inside rectangle k (later ones win)."""
    res = spec.resolution
    ext_x = np.abs(rects.half[:, 0] * rects.cos) + np.abs(rects.half[:, 1] * rects.sin)
    ext_y = np.abs(rects.half[:, 0] * rects.sin) + np.abs(rects.half[:, 1] * rects.cos)
    for k in range(len(rects)):
        cx, cy = rects.center[k]
        c0 = max(0, int(np.floor((cx - ext_x[k] - spec.x0) / res)))
        c1 = min(spec.cols, int(np.ceil((cx + ext_x[k] - spec.x0) / res)) + 1)
        r0 = max(0, int(np.floor((cy - ext_y[k] - spec.y0) / res)))
        r1 = min(spec.rows, int(np.ceil((cy + ext_y[k] - spec.y0) / res)) + 1)
        if c0 >= c1 or r0 >= r1:
            continue
        dx = (spec.x0 + (np.arange(c0, c1) + 0.5) * res - cx)[None, :]
        dy = (spec.y0 + (np.arange(r0, r1) + 0.5) * res - cy)[:, None]
        inside = (np.abs(dx * rects.cos[k] + dy * rects.sin[k]) <= rects.half[k, 0]) \
            & (np.abs(-dx * rects.sin[k] + dy * rects.cos[k]) <= rects.half[k, 1])
        out[r0:r1, c0:c1][inside] = labels[k]


@dataclass
class SightGrid:
    """What blocks a line of sight, per cell: 0 nothing, ``WALL``, or the id of a tall object."""

    spec: GridSpec
    labels: NDArray[np.int32]

    @classmethod
    def from_scene(cls, spec: GridSpec, walls: RectSet, objects: Sequence[tuple[int, RectSet, float]],
                   block_height: float = BLOCK_HEIGHT_M) -> SightGrid:
        """``objects``: (instance id, its footprint as a one-rectangle set, its height in m)."""
        labels = np.zeros((spec.rows, spec.cols), dtype=np.int32)
        label_rects(spec, walls, [WALL] * len(walls), labels)
        for oid, rect, height in objects:
            if height >= block_height:
                label_rects(spec, rect, [int(oid)], labels)
        return cls(spec, labels)

    def sees(self, xy: Sequence[float] | NDArray[np.floating], footprint: NDArray[np.floating],
             own_ids: Sequence[int] = ()) -> bool:
        """True when some point of ``footprint`` (its corners, edges and centre) is in sight of ``xy``.

        Cells of ``own_ids`` (the object itself) never block; a line is tested at a quarter of a
        cell, so no wall cell is stepped over."""
        fp = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
        if fp.size == 0:
            return False
        res = self.spec.resolution
        targets = [fp, fp.mean(axis=0, keepdims=True)]
        for a, b in zip(fp, np.roll(fp, -1, axis=0), strict=True):  # edge points every cell
            n = max(int(np.ceil(np.linalg.norm(b - a) / res)), 1)
            t = np.linspace(0.0, 1.0, n + 1)[1:-1, None]
            targets.append(a + t * (b - a))
        tgt = np.vstack(targets)
        p = np.asarray(xy, dtype=np.float64).reshape(2)
        length = np.linalg.norm(tgt - p, axis=1)
        n = max(int(np.ceil(length.max() / (res / 4))), 1)
        t = np.linspace(0.0, 1.0, n + 1)
        pts = p[None, None, :] + t[None, :, None] * (tgt - p)[:, None, :]  # (targets, samples, 2)
        rc = self.spec.to_cell(pts.reshape(-1, 2)).reshape(len(tgt), n + 1, 2)
        r, c = rc[..., 0], rc[..., 1]
        inside = (r >= 0) & (r < self.spec.rows) & (c >= 0) & (c < self.spec.cols)
        lab = np.where(inside, self.labels[np.clip(r, 0, self.spec.rows - 1), np.clip(c, 0, self.spec.cols - 1)], 0)
        blocked = (lab != 0) & ~np.isin(lab, np.asarray(list(own_ids), dtype=np.int32))
        return bool((~blocked.any(axis=1)).any())


def sight_grid(apartment: object, spec: GridSpec, block_height: float = BLOCK_HEIGHT_M) -> SightGrid:
    """The sight-blocking grid of a simulator apartment (walls and tall objects) on ``spec``."""
    objs = []
    for o in apartment.manifest.objects:  # type: ignore[attr-defined]
        rect = RectSet.from_lists([(o.center[0], o.center[1])], [(o.size[0], o.size[1])], [o.yaw])
        objs.append((int(o.id), rect, float(o.center[2] + o.size[2] / 2.0)))
    return SightGrid.from_scene(spec, apartment.wall_rects, objs, block_height)  # type: ignore[attr-defined]
