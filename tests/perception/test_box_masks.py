"""Depth masks of furniture seen whole, at a slant and cut by the image border: the box's
surfaces split where a face stops facing up (a seat, a bed's top) and at creases, and neither is
an occlusion; a surface that fills what the image border leaves of a ring side is no wall."""

from __future__ import annotations

import numpy as np
import pytest
from _synth_scene import Box, look_at, render

from capnav.core.geometry import Intrinsics
from capnav.perception import box_from_mask
from capnav.perception.box_masks import depth_box_mask, floor_pixels, up_facing_pixels

K = Intrinsics.from_fov(320, 240, 70.0)
RED, DARK = (200, 40, 40), (120, 30, 30)
# A sofa against the far wall: a seat on a plinth, a backrest, two arms.
SOFA = [Box((-1.0, 2.1, 0.1), (1.0, 2.9, 0.45), 1, 1, RED), Box((-1.0, 2.7, 0.45), (1.0, 2.9, 0.9), 1, 1, DARK),
        Box((-1.0, 2.1, 0.45), (-0.8, 2.9, 0.65), 1, 1, DARK), Box((0.8, 2.1, 0.45), (1.0, 2.9, 0.65), 1, 1, DARK),
        Box((-1.0, 2.15, 0.0), (1.0, 2.25, 0.1), 1, 1, RED)]


def _mask(eye: tuple[float, float, float], target: tuple[float, float, float], margin: float = 6.0
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sofa's depth mask from a detector's box: the true box grown 3%, but never closer than
    ``margin`` px to the image border (a detector's box of a cut-off object stops short of it)."""
    f = render(SOFA, look_at(eye, target), K)
    inst = np.asarray(f.gt_instance) == 1
    x0, y0, x1, y1 = box_from_mask(inst)
    g = 0.03 * (x1 - x0)
    box = (max(margin, x0 - g), max(margin, y0 - g), min(K.width - margin, x1 + g), min(K.height - margin, y1 + g))
    up = up_facing_pixels(f.depth, K, f.T_wc)
    m = depth_box_mask(f.depth, box, exclude=floor_pixels(f.depth, K, f.T_wc), up=up)
    return m, inst, up


@pytest.mark.parametrize("eye,target", [((0.6, 1.0, 1.1), (0.2, 2.5, 0.5)), ((-0.9, 0.6, 1.3), (-0.2, 2.5, 0.45))])
def test_a_sofa_seen_at_a_slant_keeps_its_seat_and_its_back(eye, target) -> None:  # type: ignore[no-untyped-def]
    m, inst, up = _mask(eye, target)
    seat = inst & up
    assert seat.sum() > 1000 and (inst & ~up).sum() > 1000
    assert (m & seat).sum() >= 0.9 * seat.sum()  # the seat meets the front at a crease: it is not hidden
    assert (m & inst & ~up).sum() >= 0.9 * (inst & ~up).sum()
    assert (m & ~inst).sum() <= 0.05 * m.sum()


def test_a_sofa_cut_by_the_image_border_is_no_wall() -> None:
    m, inst, _ = _mask((0.2, 1.5, 0.9), (-0.6, 2.2, 0.1))
    r, c = np.flatnonzero(inst.any(axis=1)), np.flatnonzero(inst.any(axis=0))
    assert r[0] == 0 and r[-1] == K.height - 1 and c[-1] == K.width - 1  # it runs out of the image on three sides
    assert (m & inst).sum() >= 0.9 * inst.sum()
    assert (m & ~inst).sum() <= 0.05 * m.sum()

