"""A thing whose box mask holds only the table top it stands on (the failure on the real TUM desk
frame: a bottle 0.2 m before a panel, 2.6 m from the camera, lifted as a 0.02 m-tall slab of the
desk top in front of it) is re-cut to the thing standing on that surface; a magazine lying flat,
whose mask is flat because the magazine is, keeps its mask. The scene is ray-cast here: a table
top at 0.75 m, a panel behind it, a bottle-sized box on the table, seen from 1.6 m looking down."""

from __future__ import annotations

import numpy as np

from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.mapping.support import SupportCutConfig, _world_points, cut_at_support

K = Intrinsics(260.0, 260.0, 159.5, 119.5, 320, 240)
TOP, PANEL_Y = 0.75, 2.3


def _look(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    d = target - eye
    return look_at_pose(eye, float(np.arctan2(d[1], d[0])), float(-np.arctan2(d[2], np.hypot(d[0], d[1]))))


def _render(box_lo: np.ndarray, box_hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Depth (m) of the scene, which surface each pixel sees (0 table, 1 panel, 2 box), and T_wc."""
    T = _look(np.array([0.0, 0.0, 1.6]), np.array([0.0, 2.0, 0.8]))
    v, u = np.mgrid[0:K.height, 0:K.width].astype(np.float64)
    ray_c = np.stack([(u - K.cx) / K.fx, (v - K.cy) / K.fy, np.ones_like(u)], axis=-1)  # depth = t
    ray = ray_c @ T[:3, :3].T
    e = T[:3, 3]
    t = np.full((*u.shape, 3), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        tt = (TOP - e[2]) / ray[..., 2]
        p = e + tt[..., None] * ray
        t[..., 0] = np.where((tt > 0) & (p[..., 1] < PANEL_Y) & (np.abs(p[..., 0]) < 1.0), tt, np.inf)
        tp = (PANEL_Y - e[1]) / ray[..., 1]
        p = e + tp[..., None] * ray
        t[..., 1] = np.where((tp > 0) & (p[..., 2] >= TOP) & (p[..., 2] < 1.6), tp, np.inf)
        t1, t2 = (box_lo - e) / ray, (box_hi - e) / ray
        near, far = np.minimum(t1, t2).max(axis=-1), np.maximum(t1, t2).min(axis=-1)
        t[..., 2] = np.where((near <= far) & (near > 0), near, np.inf)
    which = t.argmin(axis=-1)
    depth = t.min(axis=-1)
    depth = np.where(np.isfinite(depth), np.round(depth * 500) / 500, 0.0)  # Kinect-like 2 mm steps
    return depth.astype(np.float32), np.where(np.isfinite(t.min(axis=-1)), which, -1), T


def _box_of(sel: np.ndarray, grow: float = 0.3) -> tuple[float, float, float, float]:
    """The box a detector draws: the pixels' rectangle, a little loose (``grow`` of its size)."""
    vs, us = np.nonzero(sel)
    gu, gv = grow * (us.max() + 1 - us.min()) / 2, grow * (vs.max() + 1 - vs.min()) / 2
    return (float(max(us.min() - gu, 0)), float(max(vs.min() - gv, 0)), float(min(us.max() + 1 + gu, K.width)),
            float(min(vs.max() + 1 + gv, K.height)))


def _cut(depth: np.ndarray, T: np.ndarray, mask: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray:
    x0, y0, x1, y1 = box  # the crop lift_detection passes: the box and 2 px around it
    c0, r0, c1, r1 = max(int(x0) - 2, 0), max(int(y0) - 2, 0), min(int(x1) + 2, K.width), min(int(y1) + 2, K.height)
    out = cut_at_support(mask[r0:r1, c0:c1], depth[r0:r1, c0:c1], K, T, (r0, c0), box, True, SupportCutConfig())
    full = np.zeros_like(mask)
    full[r0:r1, c0:c1] = out
    return full


def test_a_bottle_whose_mask_is_the_table_top_is_cut_to_the_bottle() -> None:
    lo, hi = np.array([-0.04, 2.06, TOP]), np.array([0.04, 2.14, TOP + 0.3])
    depth, which, T = _render(lo, hi)
    bottle = which == 2
    box = _box_of(bottle)
    x0, y0, x1, y1 = (int(v) for v in box)
    inbox = np.zeros_like(bottle)
    inbox[y0:y1, x0:x1] = True
    mask = inbox & (which == 0)  # what the box mask took: the desk top at the box's foot
    assert mask.sum() > 10
    out = _cut(depth, T, mask, box)
    z = _world_points(depth.astype(np.float64), K, T, (0, 0))[..., 2]
    assert out.sum() > 0.5 * bottle.sum(), (out.sum(), bottle.sum())
    assert (out & bottle).sum() >= 0.9 * out.sum()  # the bottle, not the panel behind it
    assert float(z[out].max() - z[out].min()) > 0.2  # as tall as the bottle, not a slab of the table


def test_a_magazine_lying_flat_keeps_its_flat_mask() -> None:
    lo, hi = np.array([-0.12, 1.9, TOP]), np.array([0.12, 2.08, TOP + 0.005])
    depth, which, T = _render(lo, hi)
    mag = which == 2
    box = _box_of(mag, 0.0)
    out = _cut(depth, T, mag, box)
    assert (out == mag).all()
