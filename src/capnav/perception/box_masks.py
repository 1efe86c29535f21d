"""Instance masks from detector boxes, for detectors that predict boxes only (COCO detectors, OWL-ViT).

The mapper lifts a detection's mask into 3D, so a filled box would smear the wall or floor
behind an object into its instance, and the object's size (a caption's "1.4 m wide") with it.
``depth_box_mask`` keeps the object's own pixels. The default ``method="surfaces"``
(``surface_mask``) cuts the box and a ring around it into smooth depth surfaces and drops the
background ones: those that run on out of the box on two sides (walls, a far room) and those
seen only through the object (the wall between chair slats, under a table); of the rest, the
group of touching surfaces that fills the box and is least hidden is the object. The floor
touches every object's base smoothly, so it is excluded first when the camera pose is known
(``floor_pixels``). ``method="mode"`` (the first method, and the fallback when no
surface qualifies) finds the strong depth modes inside the box (``band``-wide depth slabs
holding at least ``min_mode_frac`` of the strongest slab's pixels), takes the pixels within
``band / 2`` of the nearest one and their largest 8-connected component, and grows that along
smooth depth up to ``extent`` metres behind the mode: a thin or see-through object (an open
chair frame) is too weak a mode next to the wall behind it, and the wall is taken instead.
Invalid depth (0, non-finite) is never part of a depth mask: it would not reach a voxel anyway.
``filled_box_mask`` is the plain box.

Measured by ``benchmarks/bench_box_masks.py`` (true boxes grown by 5%, Sweet Home 3D apartments,
640x480; numbers in the README): the median IoU with the true instance mask and the share of
mask pixels off the instance, per category, for both methods. The known failure of both is an
occluder in front of the object filling a large part of its box (a table behind its chairs).
``mask="sam"`` of the owl detector is the better choice when a SAM folder is at hand.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from capnav.core.errors import InputError
from capnav.perception.depth_edges import SHIFTS, attach_to_nearest, depth_jumps, depth_kinks, shift

Box = tuple[float, float, float, float]

_EIGHT = np.ones((3, 3), dtype=bool)
MASK_METHODS = ("surfaces", "mode")


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
                   gap_rel: float = 0.02, exclude: NDArray[np.bool_] | None = None,
                   method: str = "surfaces", up: NDArray[np.bool_] | None = None) -> NDArray[np.bool_]:
    """The object in ``box``.

    ``method="surfaces"`` (default, ``surface_mask``): the box's smooth surfaces minus the
    background ones (those that run out of the box on two sides, and those seen only through
    the object), falling back to the mode method when no surface is left. ``method="mode"``: the
    pixels within ``band / 2`` of the nearest strong depth mode's median depth, their largest
    8-connected component, grown along smooth depth up to ``extent`` metres behind the mode
    (``grow_smooth``). ``exclude`` (H, W) marks pixels that belong to no object (the floor,
    ``floor_pixels``). ``up`` (H, W) marks pixels whose surface faces up (``up_facing_pixels``):
    where it changes, one surface ends and another begins (a table top and the wall it touches,
    seen at a slant, meet without a depth jump). Returns an empty mask when the box holds fewer
    than ``min_valid`` usable depth pixels.
    """
    if method not in MASK_METHODS:
        raise InputError(f"unknown depth mask method {method!r}; available: {', '.join(MASK_METHODS)}")
    if band <= 0 or bin_size <= 0:
        raise InputError(f"depth mask band and bin_size must be > 0, got {band} and {bin_size}")
    z = np.asarray(depth)
    if z.ndim != 2:
        raise InputError(f"depth must be (H, W), got shape {z.shape}")
    if exclude is not None and np.shape(exclude) != z.shape:
        raise InputError(f"exclude mask shape {np.shape(exclude)} != depth shape {z.shape}")
    if up is not None and np.shape(up) != z.shape:
        raise InputError(f"up mask shape {np.shape(up)} != depth shape {z.shape}")
    mask = np.zeros(z.shape, dtype=bool)
    c0, r0, c1, r1 = box_pixels(box, (z.shape[0], z.shape[1]))
    crop = z[r0:r1, c0:c1].astype(np.float64)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(crop) & (crop > 0)
    if exclude is not None:
        valid &= ~np.asarray(exclude, dtype=bool)[r0:r1, c0:c1]
    if int(valid.sum()) < max(1, min_valid):
        return mask
    if method == "surfaces":
        surf = surface_mask(z, (c0, r0, c1, r1), exclude, extent=extent, gap=gap, gap_rel=gap_rel, min_valid=min_valid,
                            up=up)
        if surf is not None:
            return surf
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
    jump = depth_jumps(z, ok, gap, gap_rel)
    labels, _ = ndimage.label(ok & ~jump)  # 4-connected: a one-pixel jump line separates regions
    hit = np.unique(labels[seed & (labels > 0)])
    grown = np.isin(labels, hit[hit > 0]) | (seed & ok)
    add = np.zeros_like(grown)
    for dy, dx in SHIFTS:
        nb_in = shift(grown, dy, dx, False)
        nb_z = shift(z, dy, dx, 0.0)
        add |= ok & ~grown & nb_in & (np.abs(z - nb_z) <= tol)
    return grown | add


def _group(main: int, zmean: NDArray[np.float64], hidden: NDArray[np.float64], background: NDArray[np.bool_],
           n_in: NDArray[np.float64], ab: NDArray[np.int64], extent: float, front: float, hidden_frac: float
           ) -> NDArray[np.bool_]:
    """Surfaces (by label) that make one object with surface ``main`` (see ``surface_mask``)."""
    z0 = zmean[main]
    ok_l = ~background & (n_in > 0) & (zmean <= z0 + extent) & (zmean >= z0 - front) & ~(
        (hidden > hidden_frac) & (zmean > z0))
    ok_l[0] = False
    ok_l[main] = True
    # Surfaces join only through touching accepted surfaces: a same-depth blob elsewhere in the box
    # is another thing.
    e = ab[:, ok_l[ab[0]] & ok_l[ab[1]]]
    nb = len(zmean)
    _, comp = connected_components(coo_matrix((np.ones(e.shape[1]), (e[0], e[1])), shape=(nb, nb)), directed=False)
    return ok_l & (comp == comp[main])


def surface_mask(depth: NDArray[np.floating], box_px: tuple[int, int, int, int],
                 exclude: NDArray[np.bool_] | None = None, extent: float = 1.5, gap: float = 0.04,
                 gap_rel: float = 0.02, ring: float = 0.1, side_frac: float = 0.3, hidden_frac: float = 0.5,
                 min_valid: int = 4, min_share: float = 0.02, front: float = 0.75, kink: float = 0.03,
                 max_leads: int = 8, fill_tol: float = 0.8, up: NDArray[np.bool_] | None = None,
                 min_occlusion: float = 0.25) -> NDArray[np.bool_] | None:
    """The object's own surfaces in the pixel window ``box_px`` (x0, y0, x1, y1), or None.

    A box from a detector frames one object; what else it catches is background, seen around
    the object or through it (an open chair back, the gap under a table). The window grown by a
    ``ring`` of its size is cut into smooth surfaces at depth jumps (``depth_jumps``, far side
    only, so a one-pixel chair leg stays whole), creases (``depth_kinks``) and, given ``up``
    (``up_facing_pixels``), where a surface stops facing up (``facing_up``: a table top against
    the wall behind it, which a slanted view shows with neither a jump nor a crease in depth, is
    never one surface with it); cut pixels rejoin
    the neighbour of nearest depth. For each surface: its pixels in the box, how much of each ring
    side (above, below, left, right of the box) it covers (the outer half of the strip: a surface
    there runs on past the box, not just over a tight box's edge; a strip the image border clips
    to less than half its width says nothing), and the share of its occluding outline (depth
    jumps to its neighbours; without ``up`` the floor and invalid pixels count too; at least
    ``min_occlusion`` of its whole outline) where it is the far side (``hidden``): the wall seen
    under a table between its legs is hidden, a seat meeting the sofa's front at a crease is not.
    A surface covering at least ``side_frac`` of two ring sides runs on past the object (a wall,
    the floor, a far room) and is background. Each of the ``max_leads`` largest surfaces (at
    least ``min_share`` of the box's valid pixels, not mostly hidden) leads a group; the surfaces
    touching the group join it unless they are background, lie more than ``extent`` metres
    behind the lead's mean depth or ``front`` metres before it (an occluder), or are mostly
    hidden (share > ``hidden_frac``) and behind it (the wall between chair slats or table legs).
    A detector draws its box around the object, so the groups whose bounding rectangle fills at
    least ``fill_tol`` of the best filling one compete; the one whose lead has most box pixels,
    weighted by how little of its outline is hidden, wins (an object occludes what lies behind
    it, never the reverse). None when no surface qualifies (``depth_box_mask`` then falls back to
    ``method="mode"``).
    """
    z_all = np.asarray(depth, dtype=np.float64)
    h, w = z_all.shape
    c0, r0, c1, r1 = box_px
    bh, bw = r1 - r0, c1 - c0
    if bh <= 0 or bw <= 0:
        return None
    mr, mc = max(2, round(ring * bh)), max(2, round(ring * bw))
    R0, R1, C0, C1 = max(0, r0 - mr), min(h, r1 + mr), max(0, c0 - mc), min(w, c1 + mc)
    z = z_all[R0:R1, C0:C1]
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(z) & (z > 0)
    if exclude is not None:
        ok &= ~np.asarray(exclude, dtype=bool)[R0:R1, C0:C1]
    z = np.where(ok, z, 0.0)
    inb = np.zeros(z.shape, dtype=bool)
    inb[r0 - R0: r1 - R0, c0 - C0: c1 - C0] = True
    n_valid = int((ok & inb).sum())
    if n_valid < max(1, min_valid):
        return None
    tol = gap + gap_rel * z
    jump = depth_jumps(z, ok, gap, gap_rel, far_only=True) | depth_kinks(z, ok, kink, 0.5 * gap_rel)
    if up is not None:  # up-facing and other pixels never share a surface
        u = facing_up(np.asarray(up, dtype=bool)[R0:R1, C0:C1], ok)
        la, na = ndimage.label(ok & ~jump & u)
        lb, n = ndimage.label(ok & ~jump & ~u)
        labels, n = np.where(la > 0, la, np.where(lb > 0, lb + na, 0)), na + n
    else:
        labels, n = ndimage.label(ok & ~jump)
    if n == 0:
        return None
    labels = attach_to_nearest(z, labels.astype(np.int64), ok & jump, tol)
    nb = n + 1
    n_in = np.bincount(labels[inb], minlength=nb).astype(np.float64)
    n_in[0] = 0.0
    count = np.bincount(labels.ravel(), minlength=nb).astype(np.float64)
    zmean = np.bincount(labels.ravel(), weights=z.ravel(), minlength=nb) / np.maximum(count, 1.0)
    sides = np.zeros(nb, dtype=np.int64)
    rows, cols = slice(r0 - R0, r1 - R0), slice(c0 - C0, c1 - C0)
    # Each side's evidence is the outer half of its ring strip (a surface there runs on past the box,
    # not over a tight box's edge); a strip the image border clips to less than half its width is no
    # evidence either way (an object cut by the border fills what is left of it).
    ht, hb, wl, wr = r0 - R0, R1 - r1, c0 - C0, C1 - c1
    outer = ((labels[: (ht + 1) // 2, cols], ht, mr), (labels[R1 - R0 - (hb + 1) // 2:, cols], hb, mr),
             (labels[rows, : (wl + 1) // 2], wl, mc), (labels[rows, C1 - C0 - (wr + 1) // 2:], wr, mc))
    for strip, width, full in outer:
        if strip.size and 2 * width >= full:
            sides += np.bincount(strip.ravel(), minlength=nb) >= side_frac * strip.size
    background = sides >= 2
    # Outline pairs (4-neighbours with different labels): which side is farther.
    hid = np.zeros(nb)
    edge = np.zeros(nb)
    jedge = np.zeros(nb)
    pairs: list[NDArray[np.int64]] = []
    for a_l, b_l, a_z, b_z in ((labels[1:], labels[:-1], z[1:], z[:-1]),
                               (labels[:, 1:], labels[:, :-1], z[:, 1:], z[:, :-1])):
        diff = a_l != b_l
        pair = diff & (a_l > 0) & (b_l > 0)
        la, lb, za, zb = a_l[pair], b_l[pair], a_z[pair], b_z[pair]
        if up is None:  # the whole outline, the floor and invalid pixels included
            edge += np.bincount(a_l[diff], minlength=nb) + np.bincount(b_l[diff], minlength=nb)
        else:  # only against other surfaces: the wall under a table, between its legs, borders the floor
            edge += np.bincount(la, minlength=nb) + np.bincount(lb, minlength=nb)
        # Only a depth jump occludes: at a crease (a seat meeting the sofa's front, a table top its
        # edge) neither surface hides behind the other.
        jmp = np.abs(za - zb) > gap + gap_rel * np.maximum(za, zb)
        jedge += np.bincount(la, weights=jmp.astype(np.float64), minlength=nb)
        jedge += np.bincount(lb, weights=jmp.astype(np.float64), minlength=nb)
        if up is None:  # without the pose the floor and invalid pixels count as a non-hiding outline
            jedge += np.bincount(a_l[diff & ~pair], minlength=nb) + np.bincount(b_l[diff & ~pair], minlength=nb)
        hid += np.bincount(la, weights=((za > zb) & jmp).astype(np.float64), minlength=nb)
        hid += np.bincount(lb, weights=((zb > za) & jmp).astype(np.float64), minlength=nb)
        pairs.append(np.stack([la, lb]))
    hidden = hid / np.maximum(np.maximum(jedge, min_occlusion * edge), 1.0)
    lead = ~background & (n_in >= max(float(min_valid), min_share * n_valid)) & (hidden <= hidden_frac)
    lead[0] = False
    if not lead.any():
        return None
    ab = np.concatenate(pairs, axis=1)
    spans = ndimage.find_objects(labels)
    lo = np.array([[s_[0].start, s_[1].start] if s_ is not None else [1 << 30, 1 << 30] for s_ in spans])
    hi = np.array([[s_[0].stop, s_[1].stop] if s_ is not None else [-1, -1] for s_ in spans])
    box_area = float(bh * bw)
    b_lo, b_hi = np.array([r0 - R0, c0 - C0]), np.array([r1 - R0, c1 - C0])
    order = np.argsort(-np.where(lead, n_in * (1.0 - hidden), -1.0))[: max(1, max_leads)]
    groups: list[tuple[float, float, NDArray[np.bool_]]] = []
    for main in order[lead[order]]:
        keep = _group(int(main), zmean, hidden, background, n_in, ab, extent, front, hidden_frac)
        members = np.flatnonzero(keep) - 1
        g_lo = np.maximum(lo[members].min(axis=0), b_lo)
        g_hi = np.minimum(hi[members].max(axis=0), b_hi)
        fill = float(np.prod(np.maximum(g_hi - g_lo, 0))) / box_area  # the box is drawn around the object
        groups.append((fill, float(n_in[main] * (1.0 - hidden[main])), keep))
    top = max(g[0] for g in groups)
    keep = max((g for g in groups if g[0] >= fill_tol * top), key=lambda g: g[1])[2]
    mask = np.zeros((h, w), dtype=bool)
    mask[R0:R1, C0:C1] = keep[labels] & inb
    return mask


def up_facing_pixels(depth: NDArray[np.floating], K: Any, T_wc: NDArray[np.floating], step: int = 2,
                     up_cos: float = 0.85) -> NDArray[np.bool_]:
    """Pixels whose depth surface faces up or down in the world (z up): table tops, seats, shelves.

    The normal is the cross product of the back-projected neighbours ``step`` px away left/right
    and above/below; it faces up when ``|n_z| >= up_cos |n|`` (within ~32 degrees). A pixel
    without four valid neighbours is not up-facing."""
    d = np.asarray(depth, dtype=np.float64)
    h, w = d.shape
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(d) & (d > 0)
    z = np.where(ok, d, 0.0)
    us = np.arange(w, dtype=np.float64)[None, :]
    vs = np.arange(h, dtype=np.float64)[:, None]
    T = np.asarray(T_wc, dtype=np.float64)
    P = np.stack([(us - K.cx) * z / K.fx, (vs - K.cy) * z / K.fy, z], axis=-1) @ T[:3, :3].T
    s = max(1, int(step))
    out = np.zeros((h, w), dtype=bool)
    if h <= 2 * s or w <= 2 * s:
        return out
    n = np.cross(P[s:-s, 2 * s:] - P[s:-s, : -2 * s], P[2 * s:, s:-s] - P[: -2 * s, s:-s])
    norm = np.linalg.norm(n, axis=-1)
    good = ok[s:-s, 2 * s:] & ok[s:-s, : -2 * s] & ok[2 * s:, s:-s] & ok[: -2 * s, s:-s] & ok[s:-s, s:-s]
    out[s:-s, s:-s] = good & (norm > 0) & (np.abs(n[..., 2]) >= up_cos * norm)
    return out


def facing_up(up: NDArray[np.bool_], ok: NDArray[np.bool_], speck: int = 1) -> NDArray[np.bool_]:
    """``up`` without specks of either kind (an opening, then a closing, by ``speck`` px: sensor
    noise flips single normals), on valid pixels."""
    u = ndimage.binary_opening(up & ok, iterations=speck)
    return np.asarray(ndimage.binary_closing(u, iterations=speck) & ok)


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
                    exclude: NDArray[np.bool_] | None = None, up: NDArray[np.bool_] | None = None,
                    K: Any | None = None, **kw: float) -> list[NDArray[np.bool_]]:
    """``depth_box_mask`` for every box of one frame; given the intrinsics ``K``, each mask keeps
    only its pieces that make one thing in 3D (``box_pieces.linked_pieces``)."""
    masks = [depth_box_mask(depth, b, band=band, exclude=exclude, up=up, **kw) for b in boxes]  # type: ignore[arg-type]
    if K is None:
        return masks
    from capnav.perception.box_pieces import linked_pieces  # it builds on this module's surfaces

    return [linked_pieces(m, depth, K) for m in masks]
