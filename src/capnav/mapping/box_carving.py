"""Drop the points of an object that its own detection boxes, seen from other views, contradict.

A chair pushed in at a table touches it in 3D: the seat's front edge comes within a few
centimetres of the apron, and the table's near edge lies inside the chair's box in most views.
Neither the box masks nor the 3D pieces (``perception.box_pieces``) can part them in one view,
so the table's edge and top join the chair and the chair is mapped as long as the table. Across
views they part. A detector draws each box around the object, so a point of the object that a
view sees (its depth agrees with the frame's depth at its pixel) lies inside that view's box;
the far end of the table, seen from the chair's side, lies outside it. Each point of an object is
counted inside or outside the box of every kept observation of the object that sees it, and a
point seen outside at least ``min_out`` times and more often than inside is dropped. A view that
does not see a point says nothing about it: a box covers what is visible, so the legs of a chair
hidden behind a table in one view fall outside that view's box and are not counted against it,
nor is a point outside the image.

The mapper keeps a small depth image of every frame an observation refers to (``DepthViews``,
min-pooled, so a thin leg stays visible) and carves each object once, before the duplicates are
merged.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.geometry import Intrinsics


@dataclass(frozen=True)
class CarveConfig:
    """Frames are kept at most ``max_side`` pixels wide (min-pooled depth, float16). A point is
    seen by a view when its depth is within ``tol + tol_rel * depth`` (m) of the kept depth at its
    pixel; it is inside a box grown by ``margin`` of the box's size (and ``margin_px``) each side
    (detector boxes are loose and jitter). Dropped: seen outside at least ``min_out`` times and
    more often than inside; an object keeps all its points when fewer than ``min_keep`` of them
    (share) or than ``min_points`` would stay."""

    enabled: bool = True
    max_side: int = 128
    tol: float = 0.05
    tol_rel: float = 0.03
    margin: float = 0.05
    margin_px: float = 4.0
    min_out: int = 2
    min_keep: float = 0.3
    min_points: int = 10


@dataclass(frozen=True)
class DepthView:
    """One frame's pooled depth (metres, 0 = none), the intrinsics of that pooled image, and the
    pose and pooling factor."""

    depth: NDArray[np.float16]
    K: Intrinsics
    T_wc: NDArray[np.float64]
    scale: int


def pooled_view(depth: NDArray[np.floating], K: Intrinsics, T_wc: NDArray[np.floating], max_side: int) -> DepthView:
    """``depth`` min-pooled by the smallest whole factor that makes it at most ``max_side`` wide
    (invalid pixels ignored; a block without valid depth is 0)."""
    d = np.asarray(depth, dtype=np.float32)
    h, w = d.shape
    s = max(1, int(np.ceil(w / max(1, max_side))))
    hh, ww = h // s, w // s
    with np.errstate(invalid="ignore"):
        v = np.where(np.isfinite(d) & (d > 0), d, np.inf)[: hh * s, : ww * s]
    m = v.reshape(hh, s, ww, s).min(axis=(1, 3))
    m = np.where(np.isfinite(m), m, 0.0).astype(np.float16)
    Ks = Intrinsics(fx=K.fx / s, fy=K.fy / s, cx=K.cx / s, cy=K.cy / s, width=max(ww, 1), height=max(hh, 1))
    return DepthView(m, Ks, np.asarray(T_wc, dtype=np.float64).copy(), s)


class DepthViews:
    """The pooled depth of the frames objects were observed in, by frame index."""

    def __init__(self, cfg: CarveConfig | None = None) -> None:
        self.cfg = cfg or CarveConfig()
        self.views: dict[int, DepthView] = {}

    def add(self, index: int, depth: NDArray[np.floating], K: Intrinsics, T_wc: NDArray[np.floating]) -> None:
        self.views[int(index)] = pooled_view(depth, K, T_wc, self.cfg.max_side)

    def keep_only(self, frames: Iterable[int]) -> None:
        """Forget the frames no observation refers to any more (bounds memory on long recordings)."""
        keep = set(frames)
        self.views = {k: v for k, v in self.views.items() if k in keep}


def box_votes(points: NDArray[np.floating], sightings: Iterable[tuple[int, tuple[float, float, float, float]]],
              views: DepthViews) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """How often each point is seen inside / outside the boxes of ``sightings`` (frame index, box
    in that frame's full-resolution pixels), counting only the views that see it."""
    cfg = views.cfg
    p = np.asarray(points, dtype=np.float64)
    n_in = np.zeros(len(p), dtype=np.int64)
    n_out = np.zeros(len(p), dtype=np.int64)
    for frame, box in sightings:
        v = views.views.get(int(frame))
        if v is None or len(p) == 0:
            continue
        R, t = v.T_wc[:3, :3], v.T_wc[:3, 3]
        c = (p - t) @ R  # camera coordinates (OpenCV: z forward)
        z = c[:, 2]
        front = z > 1e-3
        zs = np.where(front, z, 1.0)
        u = v.K.fx * c[:, 0] / zs + v.K.cx
        r = v.K.fy * c[:, 1] / zs + v.K.cy
        hh, ww = v.depth.shape
        ui, ri = np.floor(u).astype(np.int64), np.floor(r).astype(np.int64)
        inside_img = front & (ui >= 0) & (ui < ww) & (ri >= 0) & (ri < hh)
        d = np.zeros(len(p))
        d[inside_img] = v.depth[ri[inside_img], ui[inside_img]].astype(np.float64)
        seen = inside_img & (d > 0) & (np.abs(z - d) <= cfg.tol + cfg.tol_rel * z)
        x0, y0, x1, y1 = (float(b) / v.scale for b in box)
        mx = cfg.margin * (x1 - x0) + cfg.margin_px / v.scale
        my = cfg.margin * (y1 - y0) + cfg.margin_px / v.scale
        in_box = (u >= x0 - mx) & (u <= x1 + mx) & (r >= y0 - my) & (r <= y1 + my)
        n_in += seen & in_box
        n_out += seen & ~in_box
    return n_in, n_out


def carve(points: NDArray[np.floating], sightings: Iterable[tuple[int, tuple[float, float, float, float]]],
          views: DepthViews) -> NDArray[np.bool_]:
    """Which of ``points`` to keep (see the module docstring); all of them when carving would
    leave too few."""
    cfg = views.cfg
    keep = np.ones(len(points), dtype=bool)
    if not cfg.enabled or len(points) == 0:
        return keep
    n_in, n_out = box_votes(points, sightings, views)
    drop = (n_out >= cfg.min_out) & (n_out > n_in)
    left = int((~drop).sum())
    if left < max(cfg.min_points, cfg.min_keep * len(points)):
        return keep
    return np.asarray(~drop)
