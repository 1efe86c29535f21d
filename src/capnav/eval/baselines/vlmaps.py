"""VLMaps-style baseline: query the dense voxel features with the goal text, go to a best region.

As in VLMaps (Huang et al. 2023), the goal text is embedded and compared with every voxel's fused
feature; the top-down map keeps each cell's best voxel score (objects only: voxels above the floor).
Cells within ``margin`` of the best score form candidate regions (8-connected components); like
VLMaps' "move to object", the agent goes to the nearest such region (``pick="best"`` takes the
region holding the single best cell instead). There are no instances and no captions: attributes
can only help as far as the dense features carry them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import ConvexHull, QhullError

from capnav.core.errors import InputError
from capnav.core.grid import GridSpec
from capnav.eval.method import METHODS, NavMethod, SceneContext
from capnav.eval.methods.base import Decision, PriorMapMethod
from capnav.planning import PlannerConfig


@dataclass(frozen=True)
class VlmapsConfig:
    margin: float = 0.1  # cosine below the best score still counted as the goal
    min_cells: int = 3  # smaller components are speckle
    z_range: tuple[float, float] = (0.05, 2.3)  # voxels that can belong to furniture (m)
    pick: str = "nearest"  # "nearest" region (VLMaps) or the region with the "best" cell

    def __post_init__(self) -> None:
        if self.pick not in ("nearest", "best"):
            raise InputError(f"VlmapsConfig.pick must be 'nearest' or 'best', got {self.pick!r}")
        if not self.margin >= 0:
            raise InputError(f"VlmapsConfig.margin must be >= 0, got {self.margin}")


def region_polygon(cells: NDArray[np.intp], spec: GridSpec) -> NDArray[np.float64]:
    """Convex hull (world x, y) of a set of cells, each cell counted by its four corners."""
    half = spec.resolution / 2
    centres = spec.to_world(cells)
    corners = (centres[:, None, :] + np.array([[-half, -half], [half, -half], [half, half], [-half, half]])[None])
    pts = corners.reshape(-1, 2)
    try:
        hull = ConvexHull(pts)
        return np.asarray(pts[hull.vertices], dtype=np.float64)
    except QhullError:  # pragma: no cover - corners of >= 1 cell always span an area
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])


def score_regions(scores: NDArray[np.floating], cfg: VlmapsConfig) -> tuple[NDArray[np.int32], int, float]:
    """Label the components of near-best cells; returns (labels, count, best score)."""
    best = float(scores.max())
    mask = scores >= best - cfg.margin
    labels, n = ndimage.label(mask, structure=np.ones((3, 3), dtype=bool))
    if n:
        sizes = ndimage.sum_labels(np.ones_like(labels), labels, index=np.arange(1, n + 1))
        small = np.flatnonzero(sizes < cfg.min_cells) + 1
        if len(small) < n:  # keep speckle only if it is all there is
            labels[np.isin(labels, small)] = 0
    return labels.astype(np.int32), int(n), best


class VlmapsStyle(PriorMapMethod):
    name = "vlmaps"

    def __init__(self, planner: PlannerConfig | None = None, config: VlmapsConfig | None = None) -> None:
        super().__init__(planner)
        self.config = config or VlmapsConfig()

    def prepare(self, ctx: SceneContext) -> None:
        space = getattr(self.cmap.voxels, "text_space", "")
        if space and space != ctx.embedder.model_id:
            raise InputError(f"the map's voxel features live in {space!r} but the embedder is "
                             f"{ctx.embedder.model_id!r}: a dense query would compare different spaces")

    def decide(self, goal_text: str, robot_xy: tuple[float, float]) -> Decision | str:
        ctx = self._ctx()
        spec = self.occ.spec
        vec = ctx.embedder.embed_one(goal_text)
        scores = self.cmap.voxels.topdown_scores(vec, spec, z_range=self.config.z_range)
        labels, _, best = score_regions(scores, self.config)
        ids = np.unique(labels[labels > 0])
        if len(ids) == 0:
            return "the voxel map has no observed cell"
        rr, cc = np.nonzero(labels)
        lab = labels[rr, cc]
        if self.config.pick == "best":
            r, c = np.unravel_index(int(np.argmax(np.where(labels > 0, scores, -np.inf))), scores.shape)
            chosen = int(labels[r, c])
        else:
            xy = spec.to_world(np.stack([rr, cc], axis=1))
            d = np.hypot(xy[:, 0] - robot_xy[0], xy[:, 1] - robot_xy[1])
            chosen = int(lab[int(np.argmin(d))])
        cells = np.stack([rr[lab == chosen], cc[lab == chosen]], axis=1)
        poly = region_polygon(cells, spec)
        centre = spec.to_world(cells).mean(axis=0)
        return Decision(poly, (float(centre[0]), float(centre[1])), None,
                        f"{self.config.pick} of {len(ids)} regions scoring >= {best - self.config.margin:.2f}",
                        f"dense score {float(scores[cells[:, 0], cells[:, 1]].max()):.3f}",
                        {"regions": len(ids), "region_cells": len(cells)})


@METHODS.register("vlmaps")
def _make(planner: PlannerConfig | None = None, **cfg: object) -> NavMethod:
    return VlmapsStyle(planner, VlmapsConfig(**cfg))  # type: ignore[arg-type]
