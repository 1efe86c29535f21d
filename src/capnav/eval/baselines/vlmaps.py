"""VLMaps-style baseline: a top-down map of dense features, queried by open-vocabulary segmentation.

As in VLMaps (Huang et al. 2023), the dense per-pixel features (here the shared LSeg stand-in,
fused in the voxel map) are pooled into a top-down grid (one weight-averaged feature per cell over
the furniture height band). A goal is localised by classifying every cell against a label list:
the goal text plus "distractor" labels (every vocabulary category the goal does not name, and
floor / wall / other), which is how VLMaps segments its map with a list of object names. Cells
won by the goal form 8-connected regions; like VLMaps' move-to-object, the agent goes to the
nearest one. When the full text wins no cell (its embedding sits between categories), the object
name it mentions is queried instead, as VLMaps' LLM parser would. There are no instances and no
captions: attributes help only as far as the dense features carry them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.spatial import ConvexHull, QhullError

from capnav.core.categories import NAMES
from capnav.core.errors import InputError
from capnav.core.grid import GridSpec
from capnav.eval.method import METHODS, NavMethod, SceneContext
from capnav.eval.methods.base import Decision, PriorMapMethod
from capnav.eval.methods.words import category_in_text
from capnav.planning import PlannerConfig

STUFF_LABELS: tuple[str, ...] = ("floor", "wall", "other")


@dataclass(frozen=True)
class VlmapsConfig:
    min_cells: int = 3  # smaller regions are speckle
    z_range: tuple[float, float] = (0.05, 2.3)  # voxels that can belong to furniture (m)
    pick: str = "nearest"  # "nearest" region (VLMaps) or the "largest"

    def __post_init__(self) -> None:
        if self.pick not in ("nearest", "largest"):
            raise InputError(f"VlmapsConfig.pick must be 'nearest' or 'largest', got {self.pick!r}")
        if self.min_cells < 1:
            raise InputError(f"VlmapsConfig.min_cells must be >= 1, got {self.min_cells}")


def region_polygon(cells: NDArray[np.intp], spec: GridSpec) -> NDArray[np.float64]:
    """Convex hull (world x, y) of a set of cells, each cell counted by its four corners."""
    half = spec.resolution / 2
    centres = spec.to_world(cells)
    corners = centres[:, None, :] + np.array([[-half, -half], [half, -half], [half, half], [-half, half]])[None]
    pts = corners.reshape(-1, 2)
    try:
        hull = ConvexHull(pts)
        return np.asarray(pts[hull.vertices], dtype=np.float64)
    except QhullError:  # pragma: no cover - the corners of >= 1 cell always span an area
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])


def topdown_features(centers: NDArray[np.floating], features: NDArray[np.floating], weights: NDArray[np.floating],
                     spec: GridSpec, z_range: tuple[float, float]) -> tuple[NDArray[np.intp], NDArray[np.float32]]:
    """Weight-averaged, L2-normalised feature of every observed cell: returns (cells (C, 2), feats (C, D))."""
    keep = (centers[:, 2] >= z_range[0]) & (centers[:, 2] <= z_range[1])
    rc = spec.to_cell(centers[keep, :2])
    inside = spec.inside(rc)
    rc, f, w = rc[inside], np.asarray(features)[keep][inside], np.asarray(weights, dtype=np.float64)[keep][inside]
    if len(rc) == 0:
        return np.zeros((0, 2), dtype=np.intp), np.zeros((0, np.asarray(features).shape[1]), dtype=np.float32)
    flat = rc[:, 0] * spec.cols + rc[:, 1]
    cells, inv = np.unique(flat, return_inverse=True)
    pool = csr_matrix((w, (inv, np.arange(len(flat)))), shape=(len(cells), len(flat)))
    agg = np.asarray(pool @ f, dtype=np.float32)
    agg /= np.maximum(np.linalg.norm(agg, axis=1, keepdims=True), 1e-12)
    return np.stack(np.divmod(cells, spec.cols), axis=1).astype(np.intp), agg


def goal_regions(won: NDArray[np.bool_], min_cells: int) -> tuple[NDArray[np.int32], list[int]]:
    """8-connected regions of cells won by the goal, without speckle (kept if it is all there is)."""
    labels, n = ndimage.label(won, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        return labels.astype(np.int32), []
    sizes = ndimage.sum_labels(np.ones_like(labels), labels, index=np.arange(1, n + 1))
    ids = [i + 1 for i in range(n) if sizes[i] >= min_cells] or list(range(1, n + 1))
    return labels.astype(np.int32), ids


class VlmapsStyle(PriorMapMethod):
    name = "vlmaps"

    def __init__(self, planner: PlannerConfig | None = None, config: VlmapsConfig | None = None) -> None:
        super().__init__(planner)
        self.config = config or VlmapsConfig()
        self.cells = np.zeros((0, 2), dtype=np.intp)
        self.feats = np.zeros((0, 0), dtype=np.float32)

    def prepare(self, ctx: SceneContext) -> None:
        vox = self.cmap.voxels
        space = getattr(vox, "text_space", "")
        if space and space != ctx.embedder.model_id:
            raise InputError(f"the map's voxel features live in {space!r} but the embedder is "
                             f"{ctx.embedder.model_id!r}: a dense query would compare different spaces")
        self.cells, self.feats = topdown_features(vox.centers(), vox.features, vox.weights, self.occ.spec,
                                                  self.config.z_range)

    def labels_for(self, goal_text: str) -> list[str]:
        """The goal first, then every label it does not name (VLMaps' list of object names)."""
        named = category_in_text(goal_text)
        return [goal_text, *(n for n in NAMES if n != named), *STUFF_LABELS]

    def segment(self, query: str) -> tuple[NDArray[np.int32], list[int]]:
        """Classify every observed cell against the label list; regions won by ``query``."""
        spec = self.occ.spec
        labels = self.labels_for(query)
        text = self.cmap.voxels.project(self._ctx().embedder.embed(labels))
        text /= np.maximum(np.linalg.norm(text, axis=1, keepdims=True), 1e-12)
        winner = (self.feats @ text.T).argmax(axis=1)  # (C,) best label of every cell
        won = np.zeros((spec.rows, spec.cols), dtype=bool)
        mine = winner == 0
        won[self.cells[mine, 0], self.cells[mine, 1]] = True
        return goal_regions(won, self.config.min_cells)

    def decide(self, goal_text: str, robot_xy: tuple[float, float]) -> Decision | str:
        spec = self.occ.spec
        if len(self.cells) == 0:
            return "the voxel map has no observed cell above the floor"
        query, note = goal_text, ""
        regions, ids = self.segment(query)
        named = category_in_text(goal_text)
        if not ids and named is not None and named != goal_text:
            # VLMaps hands its map the object name an LLM extracts from the instruction
            query, note = named, f"the full text won no cell; queried its object name {named!r}; "
            regions, ids = self.segment(query)
        if not ids:
            return f"no map cell is classified as {goal_text!r}"
        rr, cc = np.nonzero(np.isin(regions, ids))
        lab = regions[rr, cc]
        if self.config.pick == "largest":
            chosen = int(max(ids, key=lambda i: int((lab == i).sum())))
        else:
            xy = spec.to_world(np.stack([rr, cc], axis=1))
            chosen = int(lab[int(np.argmin(np.hypot(xy[:, 0] - robot_xy[0], xy[:, 1] - robot_xy[1])))])
        cells = np.stack([rr[lab == chosen], cc[lab == chosen]], axis=1)
        centre = spec.to_world(cells).mean(axis=0)
        return Decision(region_polygon(cells, spec), (float(centre[0]), float(centre[1])), None,
                        f"{note}{self.config.pick} of {len(ids)} regions classified as {query!r}",
                        f"{len(cells)} cells", {"regions": len(ids), "region_cells": len(cells)})


@METHODS.register("vlmaps")
def _make(planner: PlannerConfig | None = None, **cfg: object) -> NavMethod:
    return VlmapsStyle(planner, VlmapsConfig(**cfg))  # type: ignore[arg-type]
