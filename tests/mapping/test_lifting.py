"""Detection lifting: robust centroid depth, eq. 10 descriptor, visibility estimate, points."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics
from capnav.mapping import LiftConfig, indexed_descriptor, lift_detection, mask_descriptor, outline_visibility
from capnav.perception import Detection, box_from_mask


def _frame(depth: np.ndarray) -> Frame:
    h, w = depth.shape
    K = Intrinsics(50.0, 50.0, w / 2, h / 2, w, h)
    return Frame(0, np.full((h, w, 3), 128, np.uint8), depth.astype(np.float32), K, np.eye(4))


def test_centroid_lifting_ignores_depth_holes() -> None:
    depth = np.full((40, 60), 4.0)
    mask = np.zeros((40, 60), bool)
    mask[10:30, 20:40] = True
    depth[mask] = 2.0
    depth[18:22, 28:32] = 0.0  # a hole right at the centroid
    depth[15, 25] = np.nan
    f = _frame(depth)
    grid = np.zeros((10, 15), np.int64)
    table = np.ones((1, 4), np.float32)
    ld = lift_detection(f, Detection(box_from_mask(mask), 3, "chair", 0.8, mask), 0, grid, table)
    assert ld is not None
    u, v = 29.5, 19.5  # mask centroid
    np.testing.assert_allclose(ld.position, [(u - 30) * 2 / 50, (v - 20) * 2 / 50, 2.0], atol=1e-9)
    assert ld.distance == pytest.approx(np.linalg.norm(ld.position))
    assert np.all(np.abs(ld.points[:, 2] - 2.0) < 1e-6)  # no hole or background point
    assert len(ld.points) <= LiftConfig().max_points
    depth[mask] = 0.0
    assert lift_detection(_frame(depth), Detection(box_from_mask(mask), 3, "chair", 0.8, mask), 0, grid,
                          table) is None


def test_eq10_descriptor_is_the_pixel_mean() -> None:
    rng = np.random.default_rng(0)
    phi = rng.standard_normal((6, 8, 5)).astype(np.float32)  # stride 5 over a 30x40 image
    mask = rng.random((30, 40)) < 0.3
    direct = np.mean([phi[v * 6 // 30, u * 8 // 40] for v, u in zip(*np.nonzero(mask), strict=True)], axis=0)
    np.testing.assert_allclose(mask_descriptor(mask, phi), direct, atol=1e-5)
    grid = np.arange(48).reshape(6, 8)
    np.testing.assert_allclose(indexed_descriptor(mask, grid, phi.reshape(48, 5)), direct, atol=1e-5)
    sub = mask[5:20, 10:30]
    direct_sub = np.mean([phi[(v + 5) * 6 // 30, (u + 10) * 8 // 40] for v, u in zip(*np.nonzero(sub), strict=True)],
                         axis=0)
    np.testing.assert_allclose(indexed_descriptor(sub, grid, phi.reshape(48, 5), (5, 10), (30, 40)), direct_sub,
                               atol=1e-5)


def test_visibility_drops_with_occluders_and_truncation() -> None:
    depth = np.full((40, 40), 5.0)
    mask = np.zeros((40, 40), bool)
    mask[10:30, 10:30] = True
    depth[mask] = 3.0
    assert outline_visibility(mask, depth) == pytest.approx(1.0)
    occluded = depth.copy()
    occluded[5:35, 28:36] = 1.0  # a nearer object covers the right side
    m2 = mask & (occluded > 2.0)
    assert 0.55 < outline_visibility(m2, occluded) < 0.85
    behind = depth.copy()
    behind[5:35, 30:36] = 8.0  # a farther surface next to it is no occluder
    assert outline_visibility(mask, behind) == pytest.approx(1.0)
    cut = np.zeros((40, 40), bool)
    cut[10:30, 0:20] = True
    assert outline_visibility(cut, depth) < 0.85
