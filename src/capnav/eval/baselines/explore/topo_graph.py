"""A topological graph of the exploration stream (LM-Nav's image memory, without images).

Nodes are keyframes (every k-th frame): where the camera stood and what the shared detector saw
from there (lifted sightings). Edges join nodes the agent could travel between: consecutive
keyframes (the recording agent did drive between them) and pairs within ``edge_max_length``
whose straight segment stays in free space of an occupancy grid built from the same stream's
depth, with obstacles grown by the robot radius. No object map is made: a landmark is only ever
"what node k saw".
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import sparse
from scipy.sparse import csgraph

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.grid import FREE
from capnav.explore.online_map import OnlineMap, OnlineMapConfig
from capnav.explore.sighting import Sighting, lift


@dataclass(frozen=True)
class GraphConfig:
    keyframe_every: int = 3  # every k-th frame of the stream becomes a node
    edge_max_length: float = 3.0  # m, longest straight-line edge between non-consecutive nodes
    consecutive_max_length: float = 6.0  # m, consecutive keyframes further apart are not joined
    robot_radius: float = 0.2  # m, obstacles are grown by this for the straight-line test
    min_score: float = 0.3  # detections below this confidence do not describe a node
    map: OnlineMapConfig = field(default_factory=OnlineMapConfig)

    def __post_init__(self) -> None:
        if self.keyframe_every < 1 or self.edge_max_length <= 0 or self.robot_radius < 0:
            raise InputError("keyframe_every must be >= 1, edge_max_length > 0 and robot_radius >= 0")


@dataclass
class TopoGraph:
    """``xy`` (N, 2) node positions, ``sightings[i]`` what node i saw, ``adjacency`` (N, N) sparse
    edge lengths (m), and the depth-derived occupancy the straight-line edges were checked on."""

    xy: NDArray[np.float64]
    frame_index: NDArray[np.int64]
    sightings: list[list[Sighting]]
    adjacency: sparse.csr_matrix
    occupancy: OnlineMap

    def __len__(self) -> int:
        return len(self.xy)

    @property
    def n_edges(self) -> int:
        return int(self.adjacency.nnz // 2)

    def route(self, start: int, goal: int) -> list[int]:
        """Shortest node sequence start -> goal (empty when not connected)."""
        _, pred = csgraph.dijkstra(self.adjacency, directed=False, indices=start, return_predecessors=True)
        if start != goal and pred[goal] < 0:
            return []
        out = [goal]
        while out[-1] != start:
            out.append(int(pred[out[-1]]))
        return out[::-1]

    def distances(self, start: int) -> NDArray[np.float64]:
        return np.asarray(csgraph.dijkstra(self.adjacency, directed=False, indices=start), dtype=np.float64)

    def entry_node(self, xy: tuple[float, float]) -> int:
        """The node the agent can reach straight from ``xy`` (nearest such), else the nearest one."""
        d = np.hypot(self.xy[:, 0] - xy[0], self.xy[:, 1] - xy[1])
        free = _passable(self.occupancy, 0.0)
        for i in np.argsort(d)[:20]:
            if _segments_clear(free, self.occupancy, np.array([xy]), self.xy[[i]])[0]:
                return int(i)
        return int(np.argmin(d))


def frames_of(source: Any) -> Iterable[Frame]:
    """Frames of the shared exploration stream: an iterable of ``Frame`` or a reader with ``frames()``."""
    if source is None:
        raise InputError("LM-Nav needs the shared exploration stream (SceneContext.frames), but it is None")
    it = source.frames() if callable(getattr(source, "frames", None)) else source
    for f in it:
        if not isinstance(f, Frame):
            raise InputError(f"the exploration stream must yield Frame objects, got {type(f).__name__}")
        yield f


def build_graph(frames: Iterable[Frame], detector: Any, config: GraphConfig | None = None) -> TopoGraph:
    """One pass over the stream: fuse every frame's depth, describe and connect the keyframes."""
    cfg = config or GraphConfig()
    occ: OnlineMap | None = None
    xy: list[tuple[float, float]] = []
    idx: list[int] = []
    seen: list[list[Sighting]] = []
    for k, frame in enumerate(frames):
        cam = np.asarray(frame.T_wc, dtype=np.float64)[:3, 3]
        if occ is None:
            occ = OnlineMap((float(cam[0]), float(cam[1])), cfg.map)
        occ.update(frame)
        if k % cfg.keyframe_every:
            continue
        dets = [d for d in (detector.detect(frame) if detector is not None else []) if d.score >= cfg.min_score]
        xy.append((float(cam[0]), float(cam[1])))
        idx.append(int(frame.index))
        seen.append(lift(frame, dets))
    if occ is None or not xy:
        raise InputError("the exploration stream is empty: no frame to build the LM-Nav graph from")
    for p in xy:  # the recording agent stood on every node
        occ.mark_free_disk(p)
    pts = np.asarray(xy, dtype=np.float64)
    n = len(pts)
    # Candidate pairs: consecutive keyframes, and every pair within the straight-edge length.
    ii, jj = np.triu_indices(n, k=1)
    length = np.hypot(*(pts[ii] - pts[jj]).T)
    consecutive = (jj == ii + 1) & (length <= cfg.consecutive_max_length)
    cand = (length <= cfg.edge_max_length) & ~consecutive
    free = _passable(occ, cfg.robot_radius)
    ok = np.zeros(len(ii), bool)
    ok[cand] = _segments_clear(free, occ, pts[ii[cand]], pts[jj[cand]])
    keep = consecutive | ok
    w = np.maximum(length[keep], 1e-6)
    adj = sparse.coo_matrix((np.r_[w, w], (np.r_[ii[keep], jj[keep]], np.r_[jj[keep], ii[keep]])), shape=(n, n))
    return TopoGraph(pts, np.asarray(idx, np.int64), seen, adj.tocsr(), occ)


def _passable(occ: OnlineMap, radius: float) -> NDArray[np.bool_]:
    grid = occ.grid()
    grown = grid.inflated(radius) if radius > 0 else grid
    return np.asarray(grown.cells == FREE)


def _segments_clear(free: NDArray[np.bool_], occ: OnlineMap, a: NDArray[np.float64], b: NDArray[np.float64]
                    ) -> NDArray[np.bool_]:
    """For each segment a[i] -> b[i]: every cell sampled every half cell along it is passable,
    apart from the cells within the robot's own radius of either end (nodes may hug a wall)."""
    if len(a) == 0:
        return np.zeros(0, bool)
    spec = occ.spec
    step = 0.5 * spec.resolution
    length = np.hypot(*(b - a).T)
    m = int(np.ceil(length.max() / step)) + 1
    t = np.linspace(0.0, 1.0, m)
    pts = a[:, None, :] + (b - a)[:, None, :] * t[None, :, None]  # (S, m, 2)
    rc = spec.to_cell(pts)
    inside = spec.inside(rc)
    r = np.clip(rc[..., 0], 0, spec.rows - 1)
    c = np.clip(rc[..., 1], 0, spec.cols - 1)
    ok = inside & free[r, c]
    end_zone = occ.config.robot_radius + spec.resolution
    along = t[None, :] * length[:, None]
    ok |= (along <= end_zone) | (along >= length[:, None] - end_zone)
    return np.asarray(ok.all(axis=1))
