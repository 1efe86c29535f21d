"""Detection lifting (paper section 3.2): mask centroid to 3D, mean descriptor (eq. 10), and the
object's surface points for the persistent memory."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.frame import Frame
from capnav.perception.base import Detection


@dataclass(frozen=True)
class LiftConfig:
    """``window`` (fraction of sqrt(mask area), at least 2 px) around the mask centroid whose
    valid mask depths give the centroid's depth by median, robust to holes and to a centroid that
    falls off a concave mask. Object points come from the mask eroded by ``erode`` px (drops
    boundary noise and mixed-depth edge pixels) and within ``mad_k`` robust sigmas (at least
    ``min_band`` m) of the median depth; at most ``max_points`` per detection, evenly spaced."""

    window: float = 0.15
    erode: int = 1
    mad_k: float = 3.0
    min_band: float = 0.2
    max_points: int = 400


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


def outline_visibility(mask: NDArray[np.bool_], depth: NDArray[np.floating], gap: float = 0.05) -> float:
    """Share of the mask outline that is not next to a nearer surface or the image border."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return 0.0
    h, w = mask.shape
    y0, y1 = max(rows[0] - 1, 0), min(rows[-1] + 2, h)
    x0, x1 = max(cols[0] - 1, 0), min(cols[-1] + 2, w)
    m = mask[y0:y1, x0:x1]
    d = np.where(np.isfinite(depth[y0:y1, x0:x1]) & (depth[y0:y1, x0:x1] > 0), depth[y0:y1, x0:x1], np.inf)
    dm = np.where(m, d, np.nan)
    # Median depth of the object: a neighbour nearer than that by ``gap`` is an occluder.
    ref = float(np.nanmedian(dm[np.isfinite(dm)])) if np.isfinite(dm).any() else np.inf
    edge = m & ~ndimage.binary_erosion(m, border_value=1)
    ring = ndimage.binary_dilation(m) & ~m
    occluder = ring & (d < ref - gap)
    near_occ = ndimage.binary_dilation(occluder) & edge
    n_edge = int(edge.sum())
    border = np.zeros_like(m)
    if y0 == 0:
        border[0] = True
    if x0 == 0:
        border[:, 0] = True
    if y1 == h:
        border[-1] = True
    if x1 == w:
        border[:, -1] = True
    bad = near_occ | (m & border)
    n_total = n_edge + int((m & border).sum())
    return 1.0 - float(bad.sum()) / max(n_total, 1)


def lift_detection(frame: Frame, det: Detection, index: int, phi: NDArray[np.float32],
                   cfg: LiftConfig = LiftConfig()) -> LiftedDetection | None:
    """Lift one detection; ``None`` when its mask has no valid depth (the caller logs the skip)."""
    depth = frame.depth
    K = frame.K
    vs, us = np.nonzero(det.mask)
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
    pc = np.array([(uc - K.cx) * z / K.fx, (vc - K.cy) * z / K.fy, z])
    T = np.asarray(frame.T_wc, dtype=np.float64)
    pos = T[:3, :3] @ pc + T[:3, 3]

    core = ndimage.binary_erosion(det.mask, iterations=cfg.erode) if cfg.erode > 0 else det.mask
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
    if pz.size > cfg.max_points:
        sel = np.linspace(0, pz.size - 1, cfg.max_points).astype(np.intp)
        pv, pu, pz = pv[sel], pu[sel], pz[sel]
    cam = np.stack([(pu - K.cx) * pz / K.fx, (pv - K.cy) * pz / K.fy, pz], axis=1)
    pts = (cam @ T[:3, :3].T + T[:3, 3]).astype(np.float32)
    cols = np.asarray(frame.rgb)[pv, pu].astype(np.uint8)
    h, w = frame.shape
    return LiftedDetection(
        index=index, detection=det, position=pos, descriptor=mask_descriptor(det.mask, phi),
        points=pts, colors=cols, distance=float(np.linalg.norm(pc)),
        visibility=outline_visibility(det.mask, depth), truncated=det.truncated(w, h),
    )
