"""Depth-image edges shared by the box masks and the box pieces: where neighbouring depths jump
(an outline against what lies behind), where the profile bends (a crease against a wall), and
the re-attachment of edge pixels to the side of nearest depth.

Why a module of its own: ``box_masks`` cuts a box into surfaces and ``box_pieces`` cuts a mask
into pieces with the same edge rules, and neither may import the other's module at the top.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

SHIFTS = [(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if (dy, dx) != (0, 0)]


def shift(a: NDArray[Any], dy: int, dx: int, fill: Any) -> NDArray[Any]:
    """``out[y, x] = a[y + dy, x + dx]`` (``fill`` outside)."""
    out = np.full_like(a, fill)
    h, w = a.shape
    out[max(0, -dy): h - max(0, dy), max(0, -dx): w - max(0, dx)] = a[max(0, dy): h - max(0, -dy) or None,
                                                                         max(0, dx): w - max(0, -dx) or None]
    return out


def depth_jumps(z: NDArray[np.floating], ok: NDArray[np.bool_], gap: float = 0.04, gap_rel: float = 0.02,
                far_only: bool = False) -> NDArray[np.bool_]:
    """Pixels on either side (``far_only``: on the far side) of a neighbour step larger than
    ``gap + gap_rel * z`` (both valid). Marking the far side only keeps a one-pixel-thin near
    part (a chair leg, a lamp pole) whole while still cutting it from what lies behind."""
    z = np.asarray(z, dtype=np.float64)
    tol = gap + gap_rel * np.abs(z)
    jump = np.zeros(z.shape, dtype=bool)
    for axis in (0, 1):
        a = np.swapaxes(z, 0, axis)
        t = np.swapaxes(tol, 0, axis)
        okk = np.swapaxes(ok, 0, axis)
        step = (np.abs(a[1:] - a[:-1]) > np.maximum(t[1:], t[:-1])) & okk[1:] & okk[:-1]
        j = np.swapaxes(jump, 0, axis)  # a view: writes land in ``jump``
        if far_only:
            j[1:] |= step & (a[1:] > a[:-1])
            j[:-1] |= step & (a[:-1] > a[1:])
        else:
            j[1:] |= step
            j[:-1] |= step
    return jump


def depth_kinks(z: NDArray[np.floating], ok: NDArray[np.bool_], kink: float = 0.03, kink_rel: float = 0.01
                ) -> NDArray[np.bool_]:
    """Pixels where the depth profile bends by more than ``kink + kink_rel * z`` (second difference
    along a row or column, three valid pixels, both steps smaller than the bend threshold times
    two: a jump is no bend): the crease where an object meets a wall it stands against shows no
    depth jump, but a bend."""
    z = np.asarray(z, dtype=np.float64)
    tol = kink + kink_rel * np.abs(z)
    out = np.zeros(z.shape, dtype=bool)
    for axis in (0, 1):
        a = np.swapaxes(z, 0, axis)
        okk = np.swapaxes(ok, 0, axis)
        o = np.swapaxes(out, 0, axis)
        t = np.swapaxes(tol, 0, axis)[1:-1]
        d1, d0 = a[2:] - a[1:-1], a[1:-1] - a[:-2]
        bend = (np.abs(d1 - d0) > t) & (np.abs(d1) <= 2.0 * t) & (np.abs(d0) <= 2.0 * t)
        o[1:-1] |= bend & okk[2:] & okk[1:-1] & okk[:-2]
    return out


def attach_to_nearest(z: NDArray[np.float64], labels: NDArray[np.int64], free: NDArray[np.bool_],
                      tol: NDArray[np.float64]) -> NDArray[np.int64]:
    """Give each ``free`` pixel the label of its 8-neighbour of nearest depth (within ``tol``)."""
    best = np.full(z.shape, np.inf)
    out = labels.copy()
    for dy, dx in SHIFTS:
        nb_l = shift(labels, dy, dx, 0)
        diff = np.abs(z - shift(z, dy, dx, 0.0))
        take = free & (nb_l > 0) & (diff <= tol) & (diff < best)
        out[take] = nb_l[take]
        best[take] = diff[take]
    return out
