"""Keep the pieces of a box's depth mask that make one thing in 3D.

A mask from a box (``box_masks``) holds what the image shows inside it, and through an
open-frame chair, under a table or past a tight box's edge the image shows other things: a
window frame behind the chair, the side of the cabinet beside it, a wall a metre behind. In the
image they touch the object; in 3D they are apart from it. ``linked_pieces`` cuts the mask into
smooth pieces at depth jumps (``depth_edges.depth_jumps``), takes the largest piece as the
object's core and adds, again and again, every piece that comes within ``link`` of what is
kept (single linkage in 3D). The parts of one object are joined in the world (a leg under its
seat, an arm over the seat, a backrest on its posts), so their seen points come close to each
other even where the joint itself is hidden; the background seen around or through the object
does not. A piece that is not linked is dropped only when it lies behind the kept ones
(farther, by its median depth): what is seen around or through an object is behind it, while
the far half of a table seen on both sides of a chair standing in front of it is not.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import cKDTree

from capnav.perception.depth_edges import attach_to_nearest, depth_jumps


@dataclass(frozen=True)
class PiecesConfig:
    """Pieces are split where neighbouring depths step by more than ``gap + gap_rel * depth`` (as
    the box masks split surfaces); a piece joins when one of its points lies within ``link +
    link_rel * depth`` (m) of a kept point (depth noise and the spacing of far pixels grow with
    depth). Points are sampled to at most ``max_points`` per query (the kept set) and
    ``max_piece_points`` per piece."""

    enabled: bool = True
    gap: float = 0.04
    gap_rel: float = 0.02
    link: float = 0.1
    link_rel: float = 0.02
    max_points: int = 4000
    max_piece_points: int = 600


def _sample(idx: NDArray[np.intp], n: int) -> NDArray[np.intp]:
    return idx if len(idx) <= n else idx[np.linspace(0, len(idx) - 1, n).astype(np.intp)]


def linked_pieces(mask: NDArray[np.bool_], depth: NDArray[np.floating], K: Any,
                  cfg: PiecesConfig = PiecesConfig()) -> NDArray[np.bool_]:
    """The pieces of the (H, W) ``mask`` linked in 3D to its largest piece or not behind the linked ones
    (see the module docstring); invalid-depth pixels are left as they were (they lift to nothing).
    ``K``: the camera's intrinsics (``fx``, ``fy``, ``cx``, ``cy``)."""
    if not cfg.enabled or not mask.any():
        return mask
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    r0, r1, c0, c1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
    out = mask.copy()
    out[r0:r1, c0:c1] = _linked(mask[r0:r1, c0:c1], np.asarray(depth)[r0:r1, c0:c1], K, (r0, c0), cfg)
    return out


def _linked(mask: NDArray[np.bool_], depth: NDArray[np.floating], K: Any, offset: tuple[int, int],
            cfg: PiecesConfig) -> NDArray[np.bool_]:
    d = np.asarray(depth, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        ok = mask & np.isfinite(d) & (d > 0)
    if int(ok.sum()) < 2:
        return mask
    z = np.where(ok, d, 0.0)
    jump = depth_jumps(z, ok, cfg.gap, cfg.gap_rel, far_only=True)  # a one-pixel leg stays whole
    labels, n = ndimage.label(ok & ~jump)
    if n <= 1:
        return mask
    labels = attach_to_nearest(z, labels.astype(np.int64), ok & jump, cfg.gap + cfg.gap_rel * z)
    flat = labels.ravel()
    order = np.argsort(flat, kind="stable")
    counts = np.bincount(flat, minlength=n + 1)
    starts = np.concatenate([[0], np.cumsum(counts)])
    vs, us = np.divmod(order, labels.shape[1])
    zz = z.ravel()[order]
    P = np.stack([(us + offset[1] - K.cx) * zz / K.fx, (vs + offset[0] - K.cy) * zz / K.fy, zz], axis=1)
    piece_pts = [P[starts[k]:starts[k + 1]] for k in range(n + 1)]
    sizes = counts.copy()
    sizes[0] = 0
    main = int(sizes.argmax())
    kept = np.zeros(n + 1, dtype=bool)
    kept[main] = True
    frontier = [main]
    while frontier:
        pts = np.concatenate([piece_pts[k] for k in frontier])
        tree = cKDTree(pts[_sample(np.arange(len(pts)), cfg.max_points)])
        frontier = []
        for k in np.flatnonzero(~kept[1:] & (sizes[1:] > 0)) + 1:
            q = piece_pts[k][_sample(np.arange(len(piece_pts[k])), cfg.max_piece_points)]
            reach = cfg.link + cfg.link_rel * q[:, 2]
            dist, _ = tree.query(q, distance_upper_bound=float(reach.max()))
            if bool(np.any(dist <= reach)):
                kept[k] = True
                frontier.append(int(k))
    zk = np.concatenate([piece_pts[k][:, 2] for k in np.flatnonzero(kept)])
    front = float(np.median(zk))
    for k in np.flatnonzero(~kept[1:] & (sizes[1:] > 0)) + 1:
        kept[k] = float(np.median(piece_pts[k][:, 2])) <= front  # not behind: the object's, hidden in between
    return np.asarray(mask & ~(ok & ~kept[labels]))
