"""Cut a detection at the surface it stands on, or that things stand on.

A box detector's box around a table holds the cups and books on it, and its box around a cup
holds the table top behind and under it; lifted whole, the cup's points join the table (its
size grows, and its label can be outvoted) and the cup's object reaches down to the table top.
Both boxes contain the same structure: a horizontal plane (many mask points at one height whose
depth surface faces up) with parts above it. ``cut_at_support`` finds the highest such plane in
the mask, then:

* a detection of a portable thing (a label that is no furniture category: cup, bottle, book,
  vase, bowl, laptop...) keeps only the largest connected part above the plane: the plane and
  what lies under it are the support, other parts above it are its neighbours on the table;
* a detection of furniture drops each connected part above the plane that stands on it (its
  points lie over the plane's own points), does not continue below the plane (a chair's backrest
  does: its posts are the back legs; a cup does not) and does not fill the box (the object a
  detector drew its box around: a TV on its cabinet fills the TV's box).

Works per frame, on the depth the detection was lifted from; a mask without a plane, or with
nothing above it, is returned as it was.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import Delaunay, QhullError

from capnav.core.geometry import Intrinsics
from capnav.perception.box_masks import up_facing_pixels
from capnav.perception.depth_edges import depth_jumps

_EIGHT = np.ones((3, 3), dtype=bool)


@dataclass(frozen=True)
class SupportCutConfig:
    """``bin`` (m) of the height histogram of up-facing points (``up_cos``: |normal z| at least
    this, normals from neighbours ``step`` px apart); a plane holds at least ``min_plane_frac`` of
    the mask's points (and ``min_plane_points``) within ``tol + tol_quad * depth**2`` of its height
    (depth noise grows with the square of the distance: Khoshelham and Elberink 2012 measure
    ~1.4 mm x z² for the Kinect; this is about three of those), at least ``min_height`` above
    the floor, with at least ``min_part`` pixels above it. A part above it fills
    the box when its pixel extent covers ``fill`` of the box's width and height; it continues
    below when ``under_frac`` of its points have the mask's points under the plane within
    ``cell`` (xy); it stands on the plane when ``on_frac`` of its points lie over the hull of the
    plane's points."""

    enabled: bool = True
    bin: float = 0.02
    up_cos: float = 0.85
    step: int = 2
    min_plane_frac: float = 0.08
    min_plane_points: int = 10
    min_height: float = 0.2
    tol: float = 0.012
    tol_quad: float = 0.004
    min_part: int = 8
    fill: float = 0.5
    cell: float = 0.05
    under_frac: float = 0.2
    on_frac: float = 0.7


def _world_points(depth: NDArray[np.floating], K: Intrinsics, T_wc: NDArray[np.floating],
                  offset: tuple[int, int]) -> NDArray[np.float64]:
    """(H, W, 3) world points of a depth crop whose top-left pixel is ``offset`` (row, col)."""
    h, w = depth.shape
    z = np.asarray(depth, dtype=np.float64)
    us = np.arange(w, dtype=np.float64)[None, :] + offset[1]
    vs = np.arange(h, dtype=np.float64)[:, None] + offset[0]
    cam = np.stack([(us - K.cx) * z / K.fx, (vs - K.cy) * z / K.fy, z], axis=-1)
    T = np.asarray(T_wc, dtype=np.float64)
    return np.asarray(cam @ T[:3, :3].T + T[:3, 3])


def support_plane(z: NDArray[np.float64], up: NDArray[np.bool_], cfg: SupportCutConfig, highest: bool = True
                  ) -> float | None:
    """Height of the highest (``highest=False``: the lowest) horizontal plane among mask points
    (heights ``z``, up-facing ``up``) with points above it, or None. A thing stands on the lowest
    plane in its box (a laptop's keyboard is a plane too, above the table); furniture holds
    things on its highest one."""
    n = z.size
    zu = z[up & (z >= cfg.min_height)]
    need = max(cfg.min_plane_points, cfg.min_plane_frac * n)
    if zu.size < need:
        return None
    lo = float(zu.min())
    idx = ((zu - lo) / cfg.bin).astype(np.int64)
    counts = np.bincount(idx)
    win = counts.astype(np.float64)  # mass within one bin either side (np.convolve's "same" pads a
    win[1:] += counts[:-1]  # histogram shorter than the kernel to the kernel's length: empty bins)
    win[:-1] += counts[1:]
    peaks = [k for k in range(len(win)) if win[k] >= need and win[k] >= win[max(k - 1, 0)]
             and win[k] >= win[min(k + 1, len(win) - 1)]]
    for k in sorted(peaks, reverse=highest):
        sel = np.abs(zu - (lo + (k + 0.5) * cfg.bin)) <= 1.5 * cfg.bin
        zp = float(np.median(zu[sel]))
        if int((z > zp + 2 * cfg.tol).sum()) >= cfg.min_part:
            return zp
    return None


def _cells(xy: NDArray[np.float64], cell: float) -> NDArray[np.int64]:
    ij = np.floor(xy / cell).astype(np.int64) + (1 << 20)
    return np.asarray((ij[:, 0] << 21) | ij[:, 1])


def _hull(xy: NDArray[np.float64], max_points: int = 400) -> Delaunay | None:
    """Triangulation of the plane's points (``find_simplex`` >= 0 inside their convex hull)."""
    if len(xy) > max_points:
        xy = xy[np.linspace(0, len(xy) - 1, max_points).astype(np.intp)]
    try:
        return Delaunay(xy)
    except (QhullError, ValueError):
        return None


def cut_at_support(mask: NDArray[np.bool_], depth: NDArray[np.floating], K: Intrinsics, T_wc: NDArray[np.floating],
                   offset: tuple[int, int], box: tuple[float, float, float, float], thing: bool,
                   cfg: SupportCutConfig = SupportCutConfig()) -> NDArray[np.bool_]:
    """The part of ``mask`` (a crop at ``offset`` of the frame, like ``depth``) that is the detected
    object, cut at its supporting plane (see the module docstring). ``thing``: the label is a
    portable thing, not furniture."""
    if not cfg.enabled or not mask.any():
        return mask
    d = np.asarray(depth, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(d) & (d > 0)
    m = mask & ok
    if int(m.sum()) < cfg.min_plane_points:
        return mask
    P = _world_points(np.where(ok, d, 0.0), K, T_wc, offset)
    Kc = SimpleNamespace(fx=K.fx, fy=K.fy, cx=K.cx - offset[1], cy=K.cy - offset[0])  # the crop's camera
    up = up_facing_pixels(d, Kc, T_wc, cfg.step, cfg.up_cos)
    z = P[..., 2]
    zp = support_plane(z[m], up[m], cfg, highest=not thing)
    tol = cfg.tol + cfg.tol_quad * d**2
    flat = _only_support(m, z, d, box[3] - box[1], K.fy, tol, cfg) if thing else None
    if flat is not None:
        own = _thing_over_support(ok, z, d, flat, tol, cfg)
        return own if own is not None else mask
    if zp is None:
        return mask
    above = m & (z > zp + tol)
    apart = above & ~depth_jumps(d, ok)  # two bowls side by side in the image are two parts
    if thing:  # the largest connected part above the plane: the thing the box was drawn around
        lab, n = ndimage.label(apart, structure=_EIGHT)
        if n == 0:
            return mask
        sizes = np.bincount(lab.ravel(), minlength=n + 1)
        sizes[0] = 0
        k = int(sizes.argmax())
        if sizes[k] < cfg.min_part:
            return mask
        # Its outline (cut off as jump pixels) and its foot, down to the plane (a cup's side goes on
        # down into the plane's band; the table top around it faces up).
        grow = (above & (lab == 0)) | (m & ~up & (z > zp + tol / 3))
        return np.asarray(ndimage.binary_propagation(lab == k, structure=_EIGHT, mask=(lab == k) | grow))
    plane = m & (np.abs(z - zp) <= tol)
    below = m & (z < zp - tol)
    hull = _hull(P[plane][:, :2])
    below_cells = _cells(P[below][:, :2], cfg.cell)
    labels, n = ndimage.label(apart, structure=_EIGHT)
    labels = np.where(above & (labels == 0), n + 1, labels)  # jump pixels: one more part, judged alike
    if n == 0:
        return mask
    x0, y0, x1, y1 = box
    bw, bh = max(x1 - x0, 1.0), max(y1 - y0, 1.0)
    out = mask.copy()
    for k, sl in enumerate(ndimage.find_objects(labels), start=1):
        if sl is None:
            continue
        part = labels[sl] == k
        if (sl[1].stop - sl[1].start) >= cfg.fill * bw and (sl[0].stop - sl[0].start) >= cfg.fill * bh:
            continue  # the box is drawn around it: it is the object
        cells = _cells(P[sl][part][:, :2], cfg.cell)
        if np.isin(cells, below_cells).mean() >= cfg.under_frac:
            continue  # it goes on under the plane: part of the body (a backrest on its legs)
        if hull is None or float((hull.find_simplex(P[sl][part][:, :2]) >= 0).mean()) < cfg.on_frac:
            continue  # not over the plane: beside it
        out[sl] &= ~part
    return out


def _only_support(m: NDArray[np.bool_], z: NDArray[np.float64], d: NDArray[np.float64], box_rows: float,
                  fy: float, tol: NDArray[np.float64], cfg: SupportCutConfig) -> float | None:
    """The height of the flat surface a thing's mask holds instead of the thing, or None. The
    box mask took the table top the thing stands on (it fills the box's foot, and a thin or
    see-through bottle gives few depth pixels of its own): its points span a sliver of height
    (within a few depth tolerances) where the box, at their depth, is many times as tall. Normals
    are not asked: at 2-3 m a Kinect's depth steps make a table top's normals noisy."""
    n = int(m.sum())
    if n < cfg.min_plane_points:
        return None
    zm = z[m]
    lo, zp, hi = (float(v) for v in np.percentile(zm, [5, 50, 95]))
    tall = box_rows * float(np.median(d[m])) / fy  # the box's height in metres at the mask's depth
    if zp < cfg.min_height or hi - lo > max(3 * float(np.median(tol[m])), 0.15 * tall):
        return None
    return zp


def _thing_over_support(ok: NDArray[np.bool_], z: NDArray[np.float64], d: NDArray[np.float64], zp: float,
                        tol: NDArray[np.float64], cfg: SupportCutConfig) -> NDArray[np.bool_] | None:
    """The thing in the box (the whole crop) standing on the plane at height ``zp``: the largest
    part above it, apart at depth jumps, that rises from the plane (its lowest points within a
    few tolerances of it) and does not run across the box from side to side (the wall or panel
    behind the table does); None when there is no such part (a magazine lying flat is its own
    flat mask)."""
    above = ok & (z > zp + 2 * tol)
    lab, n = ndimage.label(above & ~depth_jumps(d, ok), structure=_EIGHT)
    if n == 0:
        return None
    w = lab.shape[1]
    best, best_n = 0, cfg.min_part - 1
    for k, sl in enumerate(ndimage.find_objects(lab), start=1):
        if sl is None:
            continue
        part = lab[sl] == k
        size = int(part.sum())
        if size <= best_n or (sl[1].start <= 1 and sl[1].stop >= w - 1):
            continue  # smaller than the best, or runs across the box: background
        if float(z[sl][part].min()) > zp + 4 * float(np.median(tol[sl][part])) + 2 * cfg.bin:
            continue  # floats above the plane: something behind, not standing on it
        best, best_n = k, size
    if best == 0:
        return None
    own = lab == best
    grow = above & (lab == 0) & (d <= float(d[own].max()) + tol)  # its outline, not the far side of it
    return np.asarray(ndimage.binary_propagation(lab == best, structure=_EIGHT, mask=own | grow))


def stands_on(top: NDArray[np.floating], base: NDArray[np.floating], radius: float = 0.06, rise: float = 0.02,
              frac: float = 0.5, k: int = 16) -> bool:
    """Whether the points ``top`` stand on the points ``base``: at least ``frac`` of them have
    ``base`` points within ``radius`` (in x, y) and rise more than ``rise`` above the highest of
    those. A bowl on a desk lies within a few centimetres of the desk's points everywhere (it is
    7 cm tall), yet it is another thing, not a part of the desk mapped under a second label."""
    t = np.asarray(top, dtype=np.float64)
    b = np.asarray(base, dtype=np.float64)
    if len(t) == 0 or len(b) == 0:
        return False
    from scipy.spatial import cKDTree

    d, idx = cKDTree(b[:, :2]).query(t[:, :2], k=min(k, len(b)), distance_upper_bound=radius)
    d, idx = d.reshape(len(t), -1), idx.reshape(len(t), -1)
    found = np.isfinite(d)
    zb = np.where(found, b[np.minimum(idx, len(b) - 1), 2], -np.inf).max(axis=1)
    over = found.any(axis=1) & (t[:, 2] > zb + rise)
    return bool(over.mean() >= frac)
