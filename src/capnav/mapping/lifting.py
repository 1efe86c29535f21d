"""Detection lifting (paper section 3.2): mask centroid to 3D, mean descriptor (eq. 10), and the
object's surface points for the persistent memory."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.categories import BY_NAME
from capnav.core.frame import Frame
from capnav.mapping.support import SupportCutConfig, cut_at_support
from capnav.perception.base import Detection


@dataclass(frozen=True)
class LiftConfig:
    """``window`` (fraction of sqrt(mask area), at least 2 px) around the mask centroid whose
    valid mask depths give the centroid's depth by median, robust to holes and to a centroid that
    falls off a concave mask. Object points come from mask pixels whose depth agrees within
    ``edge_tol`` m (+1% of the depth) with the mean depth of their in-mask 3x3 neighbours (drops
    boundary noise that spills onto the background and mixed-depth edge pixels, but keeps thin
    parts such as lamp poles and chair legs that an erosion would delete), optionally eroded by
    ``erode`` px, and within ``mad_k`` robust sigmas (at least ``min_band`` m) of the median
    depth; at most ``max_points`` per detection, evenly spaced. ``support`` cuts the mask at the
    plane the object stands on or that things stand on (``mapping.support``) before any of it."""

    window: float = 0.15
    edge_tol: float = 0.05
    erode: int = 0
    mad_k: float = 4.0
    min_band: float = 0.5
    max_points: int = 400
    support: SupportCutConfig = field(default_factory=SupportCutConfig)


@dataclass
class LiftedDetection:
    """A detection with its 3D lifting: eq. 9 plus ``x_i^w`` and ``s_i`` (eq. 10)."""

    index: int  # position in the frame's detection list
    detection: Detection
    position: NDArray[np.float64]  # (3,) x_i^w
    descriptor: NDArray[np.float32]  # (D,) s_i
    points: NDArray[np.float32]  # (n, 3) world surface points
    colors: NDArray[np.uint8]  # (n, 3)
    distance: float  # camera centre to x_i^w
    visibility: float  # 1 - fraction of the outline bordering a nearer surface or the image edge
    truncated: bool
    support: float = 0.0  # m² of surface the mask covers (its 3D support: what its label votes weigh)
    camera: NDArray[np.float64] | None = None  # (3,) world camera centre of the frame (views of a place)

    @property
    def box(self) -> tuple[float, float, float, float]:
        return self.detection.box

    @property
    def class_id(self) -> int:
        return self.detection.class_id


def mask_descriptor(mask: NDArray[np.bool_], phi: NDArray[np.float32]) -> NDArray[np.float32]:
    """Eq. 10: mean of Phi over the mask pixels, Phi (H', W', D) sampled nearest at each pixel."""
    h, w = mask.shape
    hh, ww, d = phi.shape
    vs, us = np.nonzero(mask)
    if vs.size == 0:
        return np.zeros(d, dtype=np.float32)
    cells = (vs * hh // h) * ww + (us * ww // w)
    counts = np.bincount(cells, minlength=hh * ww)
    nz = np.flatnonzero(counts)
    flat = phi.reshape(hh * ww, d)
    return ((counts[nz].astype(np.float32) @ flat[nz]) / np.float32(vs.size)).astype(np.float32)


def outline_visibility(mask: NDArray[np.bool_], depth: NDArray[np.floating], gap: float = 0.05,
                       image_border: tuple[bool, bool, bool, bool] | None = None) -> float:
    """Share of the mask outline not next to a nearer surface (an occluder) nor on the image border.

    ``mask`` / ``depth`` may be a crop; ``image_border`` says which crop sides (top, left, bottom,
    right) are the image border (default: all four, i.e. the arrays are the whole image)."""
    if not mask.any():
        return 0.0
    top, left, bottom, right = image_border if image_border is not None else (True, True, True, True)
    d = np.where(np.isfinite(depth) & (depth > 0), depth, np.inf)
    zm = d[mask]
    zm = zm[np.isfinite(zm)]
    ref = float(np.median(zm)) if zm.size else np.inf
    edge = mask & ~ndimage.binary_erosion(mask, border_value=1)
    ring = ndimage.binary_dilation(mask) & ~mask
    near_occ = ndimage.binary_dilation(ring & (d < ref - gap)) & edge
    border = np.zeros_like(mask)
    if top:
        border[0] = True
    if left:
        border[:, 0] = True
    if bottom:
        border[-1] = True
    if right:
        border[:, -1] = True
    on_border = mask & border
    n_total = int(edge.sum()) + int(on_border.sum())
    return 1.0 - float((near_occ | on_border).sum()) / max(n_total, 1)


def depth_consistent(mask: NDArray[np.bool_], depth: NDArray[np.floating], tol: float) -> NDArray[np.bool_]:
    """Mask pixels whose depth is within ``tol + 1%`` of the mean of their in-mask 3x3 neighbours."""
    d = np.where(mask & np.isfinite(depth) & (depth > 0), depth, 0.0).astype(np.float64)
    m = (d > 0).astype(np.float64)
    kernel = np.ones((3, 3))
    s = ndimage.correlate(d, kernel, mode="constant") - d
    c = ndimage.correlate(m, kernel, mode="constant") - m
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = s / c
    return (m > 0) & (c > 0) & (np.abs(d - mean) <= tol + 0.01 * d)


def indexed_descriptor(mask: NDArray[np.bool_], grid: NDArray[np.integer], table: NDArray[np.float32],
                       offset: tuple[int, int] = (0, 0), image_shape: tuple[int, int] | None = None
                       ) -> NDArray[np.float32]:
    """Eq. 10 for a factored feature map ``Phi = table[grid]``; ``mask`` may be a crop of the image
    whose top-left pixel is ``offset`` (row, col) in an image of ``image_shape``."""
    h, w = image_shape if image_shape is not None else mask.shape
    hh, ww = grid.shape
    vs, us = np.nonzero(mask)
    if vs.size == 0:
        return np.zeros(table.shape[1], dtype=np.float32)
    rows = grid[(vs + offset[0]) * hh // h, (us + offset[1]) * ww // w]
    counts = np.bincount(rows, minlength=len(table))
    nz = np.flatnonzero(counts)
    return ((counts[nz].astype(np.float32) @ table[nz]) / np.float32(vs.size)).astype(np.float32)


def lift_detection(frame: Frame, det: Detection, index: int, grid: NDArray[np.integer],
                   table: NDArray[np.float32], cfg: LiftConfig = LiftConfig()) -> LiftedDetection | None:
    """Lift one detection (features as ``table[grid]``, see ``DenseFeatureEncoder.encode_indexed``);
    ``None`` when its mask has no valid depth (the caller logs the skip). Works on the box crop."""
    h, w = frame.shape
    x0, y0, x1, y1 = det.box
    c0, r0 = max(int(np.floor(x0)) - 2, 0), max(int(np.floor(y0)) - 2, 0)
    c1, r1 = min(int(np.ceil(x1)) + 2, w), min(int(np.ceil(y1)) + 2, h)
    mask = det.mask[r0:r1, c0:c1]
    if mask.sum() != det.area:  # the box does not cover the mask: fall back to the whole image
        r0, c0, r1, c1 = 0, 0, h, w
        mask = det.mask
    depth = np.asarray(frame.depth)[r0:r1, c0:c1]
    K = frame.K
    # A thing (a label that is no furniture category) keeps what stands above its support; furniture
    # sheds the things standing on it.
    mask = cut_at_support(mask, depth, K, frame.T_wc, (r0, c0), det.box, det.label not in BY_NAME, cfg.support)
    vs, us = np.nonzero(mask)
    if vs.size == 0:
        return None
    z_all = depth[vs, us]
    ok = np.isfinite(z_all) & (z_all > 0)
    if not ok.any():
        return None
    uc, vc = float(us.mean()), float(vs.mean())
    r = max(2.0, cfg.window * np.sqrt(vs.size))
    near = ok & (np.abs(us - uc) <= r) & (np.abs(vs - vc) <= r)
    if near.sum() < 3:
        near = ok
    z = float(np.median(z_all[near]))
    pc = np.array([(uc + c0 - K.cx) * z / K.fx, (vc + r0 - K.cy) * z / K.fy, z])
    T = np.asarray(frame.T_wc, dtype=np.float64)
    pos = T[:3, :3] @ pc + T[:3, 3]

    core = ndimage.binary_erosion(mask, iterations=cfg.erode) if cfg.erode > 0 else mask
    if cfg.edge_tol > 0:
        core = core & depth_consistent(mask, depth, cfg.edge_tol)
    pv, pu = np.nonzero(core)
    if pv.size < 8:
        pv, pu = vs, us
    pz = depth[pv, pu]
    good = np.isfinite(pz) & (pz > 0)
    pv, pu, pz = pv[good], pu[good], pz[good]
    if pz.size:
        med = float(np.median(pz))
        band = max(cfg.min_band, cfg.mad_k * 1.4826 * float(np.median(np.abs(pz - med))))
        keep = np.abs(pz - med) <= band
        pv, pu, pz = pv[keep], pu[keep], pz[keep]
    support = float(np.sum(pz.astype(np.float64) ** 2)) / (K.fx * K.fy)  # before the sampling below
    if pz.size > cfg.max_points:
        sel = np.linspace(0, pz.size - 1, cfg.max_points).astype(np.intp)
        pv, pu, pz = pv[sel], pu[sel], pz[sel]
    pv, pu = pv + r0, pu + c0
    cam = np.stack([(pu - K.cx) * pz / K.fx, (pv - K.cy) * pz / K.fy, pz], axis=1)
    pts = (cam @ T[:3, :3].T + T[:3, 3]).astype(np.float32)
    cols = np.asarray(frame.rgb)[pv, pu].astype(np.uint8)
    return LiftedDetection(
        index=index, detection=det, position=pos,
        descriptor=indexed_descriptor(mask, grid, table, (r0, c0), (h, w)),
        points=pts, colors=cols, distance=float(np.linalg.norm(pc)),
        visibility=outline_visibility(mask, depth, image_border=(r0 == 0, c0 == 0, r1 == h, c1 == w)),
        truncated=det.truncated(w, h), support=support, camera=T[:3, 3].copy(),
    )
