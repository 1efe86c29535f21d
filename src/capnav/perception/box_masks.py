"""Instance masks from detector boxes, for detectors that predict boxes only (OWL-ViT, OWLv2).

The mapper lifts a detection's mask into 3D, so a filled box would smear the wall or floor
behind an object into its instance. ``depth_box_mask`` keeps the object instead. Inside the box
it finds the strong depth modes (``band``-wide depth slabs holding at least ``min_mode_frac`` of
the strongest slab's pixels, so a few stray near pixels do not count), takes the pixels within
``band / 2`` of the nearest one and their largest 8-connected component, and grows that along
smooth depth (no jump between neighbours), up to ``extent`` metres behind the mode, because a
sofa or a shelf seen at a slant spans more depth than a band. Objects stand in front of what
their box also catches (walls, far furniture), so the nearest strong mode is usually the
object. The floor touches every object's base smoothly, so it is excluded first when the
camera pose is known (``floor_pixels``). Invalid depth (0, non-finite) is never part of a depth
mask: it would not reach a voxel anyway. ``filled_box_mask`` is the plain box.

Measured on boxes equal to the true instance boxes (objects >= 200 px, 160x120), median IoU
with the true mask: 0.98 on the tests' ray-cast box scenes (36 frames; 0.78 with the band
alone), 0.80 on a ``capnav sim`` apartment (seed 0, 12 frames, 39 objects; 0.53 with the band
alone, no growing and no floor removal). The known failure is an occluder in front of the
object filling a large part of its box: its surface is the nearest strong mode and is taken
instead. ``mask="sam"`` of the owl detector is the better choice when a SAM folder is at hand.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.errors import InputError

Box = tuple[float, float, float, float]

_EIGHT = np.ones((3, 3), dtype=bool)


def box_pixels(box: Box, shape: tuple[int, int]) -> tuple[int, int, int, int]:
    """Integer pixel window ``(x0, y0, x1, y1)`` (x1, y1 exclusive) covering ``box``, clipped to the image."""
    h, w = shape
    x0, y0, x1, y1 = (float(v) for v in box)
    if not all(np.isfinite(v) for v in (x0, y0, x1, y1)):
        raise InputError(f"box {box} is not finite")
    c0 = int(np.clip(np.floor(x0), 0, w))
    r0 = int(np.clip(np.floor(y0), 0, h))
    c1 = int(np.clip(np.ceil(x1), 0, w))
    r1 = int(np.clip(np.ceil(y1), 0, h))
    return c0, r0, max(c0, c1), max(r0, r1)


def filled_box_mask(box: Box, shape: tuple[int, int]) -> NDArray[np.bool_]:
    """The box itself as an (H, W) bool mask."""
    c0, r0, c1, r1 = box_pixels(box, shape)
    mask = np.zeros(shape, dtype=bool)
    mask[r0:r1, c0:c1] = True
    return mask


def depth_modes(depths: NDArray[np.floating], window: float = 0.4, bin_size: float = 0.05,
                min_mode_frac: float = 0.3) -> list[float]:
    """Depths (m) of the strong modes of ``depths`` (valid depths, > 0 and finite), nearest first.

    The mass of every ``window``-wide depth slab is counted on ``bin_size`` bins; a mode is a local
    maximum of that mass, and it is strong when it holds >= ``min_mode_frac`` of the largest
    mode's mass. Counting slabs rather than single bins lets an object whose surface spans a few
    tens of centimetres in depth compete with a flat wall behind it.
    """
    d = np.asarray(depths, dtype=np.float64).ravel()
    if d.size == 0:
        raise InputError("depth_modes needs at least one valid depth")
    lo = float(d.min())
    n_bins = max(1, int(np.ceil((float(d.max()) - lo) / bin_size)) + 1)
    counts = np.bincount(np.minimum(((d - lo) / bin_size).astype(np.int64), n_bins - 1), minlength=n_bins)
    hw = max(0, round(0.5 * window / bin_size))
    cs = np.concatenate([[0], np.cumsum(counts)])
    idx = np.arange(n_bins)
    mass = (cs[np.minimum(idx + hw + 1, n_bins)] - cs[np.maximum(idx - hw, 0)]).astype(np.float64)
    left = np.concatenate([[-1.0], mass[:-1]])
    right = np.concatenate([mass[1:], [-1.0]])
    peaks = np.flatnonzero((mass >= left) & (mass >= right) & (mass > 0))  # a plateau: each of its bins
    if peaks.size == 0:
        peaks = np.array([int(mass.argmax())])
    strong = peaks[mass[peaks] >= min_mode_frac * mass[peaks].max()]
    return [lo + (int(k) + 0.5) * bin_size for k in strong]  # bins run near to far


def nearest_depth_mode(depths: NDArray[np.floating], window: float = 0.4, bin_size: float = 0.05,
                       min_mode_frac: float = 0.3) -> float:
    """The nearest strong mode of ``depth_modes``."""
    return depth_modes(depths, window, bin_size, min_mode_frac)[0]


def depth_box_mask(depth: NDArray[np.floating], box: Box, band: float = 0.4, bin_size: float = 0.05,
                   min_mode_frac: float = 0.3, min_valid: int = 4, extent: float = 1.5, gap: float = 0.04,
                   gap_rel: float = 0.02, exclude: NDArray[np.bool_] | None = None) -> NDArray[np.bool_]:
    """The object in ``box``: the surface at the box's nearest strong depth mode.

    The pixels within ``band / 2`` of the mode's median depth, their largest 8-connected
    component, grown along smooth depth up to ``extent`` metres behind the mode
    (``grow_smooth``). ``exclude`` (H, W) marks pixels that belong to no object (the floor,
    ``floor_pixels``). Returns an empty mask when the box holds fewer than ``min_valid`` usable
    depth pixels.
    """
    if band <= 0 or bin_size <= 0:
        raise InputError(f"depth mask band and bin_size must be > 0, got {band} and {bin_size}")
    z = np.asarray(depth)
    if z.ndim != 2:
        raise InputError(f"depth must be (H, W), got shape {z.shape}")
    if exclude is not None and np.shape(exclude) != z.shape:
        raise InputError(f"exclude mask shape {np.shape(exclude)} != depth shape {z.shape}")
    mask = np.zeros(z.shape, dtype=bool)
    c0, r0, c1, r1 = box_pixels(box, (z.shape[0], z.shape[1]))
    crop = z[r0:r1, c0:c1].astype(np.float64)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(crop) & (crop > 0)
    if exclude is not None:
        valid &= ~np.asarray(exclude, dtype=bool)[r0:r1, c0:c1]
    if int(valid.sum()) < max(1, min_valid):
        return mask
    crop = np.where(valid, crop, 0.0)
    mode = nearest_depth_mode(crop[valid], band, bin_size, min_mode_frac)
    mask[r0:r1, c0:c1] = _mode_component(crop, valid, mode, 0.5 * band, extent, gap, gap_rel)
    return mask


def _mode_component(crop: NDArray[np.float64], valid: NDArray[np.bool_], mode: float, half: float, extent: float,
                    gap: float, gap_rel: float) -> NDArray[np.bool_]:
    near = crop[valid]
    z0 = float(np.median(near[np.abs(near - mode) <= half]))
    keep = valid & (np.abs(crop - z0) <= half)
    labels, n = ndimage.label(keep, structure=_EIGHT)
    if n == 0:
        return keep
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    sizes[0] = 0
    comp = labels == int(sizes.argmax())
    if extent > half:
        comp = grow_smooth(crop, valid & (crop <= z0 + extent), comp, gap, gap_rel)
    return comp


_SHIFTS = [(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if (dy, dx) != (0, 0)]


def _shift(a: NDArray[Any], dy: int, dx: int, fill: Any) -> NDArray[Any]:
    """``out[y, x] = a[y + dy, x + dx]`` (``fill`` outside)."""
    out = np.full_like(a, fill)
    h, w = a.shape
    out[max(0, -dy): h - max(0, dy), max(0, -dx): w - max(0, dx)] = a[max(0, dy): h - max(0, -dy) or None,
                                                                         max(0, dx): w - max(0, -dx) or None]
    return out


def grow_smooth(z: NDArray[np.floating], allowed: NDArray[np.bool_], seed: NDArray[np.bool_], gap: float = 0.04,
                gap_rel: float = 0.02) -> NDArray[np.bool_]:
    """Extend ``seed`` over ``allowed`` pixels reachable without crossing a depth jump.

    A jump is a neighbour step larger than ``gap + gap_rel * z`` (noise grows with depth). An
    object seen at a slant (a sofa, a bookshelf along the view) spans more depth than a band
    around its front, but its surface is smooth while its outline against the wall behind it is
    a jump. Pixels on a jump are split off, the smooth regions touching the seed kept, and the
    jump pixels on the object's side re-attached.
    """
    z = np.asarray(z, dtype=np.float64)
    ok = np.asarray(allowed, dtype=bool)
    tol = gap + gap_rel * np.abs(z)
    jump = np.zeros(z.shape, dtype=bool)
    for axis in (0, 1):
        a = np.swapaxes(z, 0, axis)
        t = np.swapaxes(tol, 0, axis)
        okk = np.swapaxes(ok, 0, axis)
        step = (np.abs(a[1:] - a[:-1]) > np.maximum(t[1:], t[:-1])) & okk[1:] & okk[:-1]
        j = np.swapaxes(jump, 0, axis)  # a view: writes land in ``jump``
        j[1:] |= step
        j[:-1] |= step
    labels, _ = ndimage.label(ok & ~jump)  # 4-connected: a one-pixel jump line separates regions
    hit = np.unique(labels[seed & (labels > 0)])
    grown = np.isin(labels, hit[hit > 0]) | (seed & ok)
    add = np.zeros_like(grown)
    for dy, dx in _SHIFTS:
        nb_in = _shift(grown, dy, dx, False)
        nb_z = _shift(z, dy, dx, 0.0)
        add |= ok & ~grown & nb_in & (np.abs(z - nb_z) <= tol)
    return grown | add


def floor_pixels(depth: NDArray[np.floating], K: Any, T_wc: NDArray[np.floating], height: float = 0.05
                 ) -> NDArray[np.bool_]:
    """Pixels whose back-projected point lies below ``height`` in the world (floor at z = 0, z up).

    No object is made of floor, and the floor touches every object's base smoothly, so the
    depth masks leave it out. Needs the README conventions (world z up, floor at 0).
    """
    d = np.asarray(depth, dtype=np.float64)
    h, w = d.shape
    T = np.asarray(T_wc, dtype=np.float64)
    us = np.arange(w, dtype=np.float64)[None, :]
    vs = np.arange(h, dtype=np.float64)[:, None]
    with np.errstate(invalid="ignore"):
        zw = T[2, 0] * (us - K.cx) / K.fx * d + T[2, 1] * (vs - K.cy) / K.fy * d + T[2, 2] * d + T[2, 3]
        return np.isfinite(d) & (d > 0) & (zw < height)


def depth_box_masks(depth: NDArray[np.floating], boxes: Sequence[Box], band: float = 0.4,
                    exclude: NDArray[np.bool_] | None = None, **kw: float) -> list[NDArray[np.bool_]]:
    """``depth_box_mask`` for every box of one frame."""
    return [depth_box_mask(depth, b, band=band, exclude=exclude, **kw) for b in boxes]  # type: ignore[arg-type]
