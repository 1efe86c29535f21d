"""Eq. 4-8 against a direct per-voxel computation, queries, and occupancy."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec
from capnav.mapping import OccupancyConfig, VoxelMap, occupancy_from_voxels, radial_weight, random_projection


def test_radial_weight_is_eq5() -> None:
    p = np.array([[0.0, 0.0, 1.0], [1.0, 2.0, 2.0], [0.0, 0.0, 0.0]], dtype=np.float32)
    sigma = 1.5
    expect = np.exp(-(p**2).sum(1) / (2 * sigma**2))
    np.testing.assert_allclose(radial_weight(p, sigma), expect, rtol=1e-6)


def test_fusion_matches_direct_weighted_average() -> None:
    rng = np.random.default_rng(3)
    res, origin = 0.1, (-0.35, 0.2, -1.0)
    vm = VoxelMap(res, origin, feature_dim=8, capacity=16)  # tiny capacity forces growth + rehash
    all_pts, all_a, all_c, all_f = [], [], [], []
    for _ in range(5):  # five "frames"
        n = 700
        pts = rng.uniform(-0.5, 0.5, (n, 3))
        a = rng.uniform(0.05, 1.0, n).astype(np.float32)
        col = rng.integers(0, 256, (n, 3)).astype(np.uint8)
        phi = rng.standard_normal((20, 8)).astype(np.float32)
        idx = rng.integers(0, 20, n)
        vm.integrate(pts, a, col, idx, phi)
        all_pts.append(pts)
        all_a.append(a)
        all_c.append(col)
        all_f.append(phi[idx])
    pts, a = np.concatenate(all_pts), np.concatenate(all_a).astype(np.float64)
    col, feat = np.concatenate(all_c).astype(np.float64), np.concatenate(all_f).astype(np.float64)
    ijk = np.floor((pts - np.array(origin)) / res).astype(int)  # eq. 4
    uniq, inv = np.unique(ijk, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    assert len(vm) == len(uniq)
    slots = vm.slots(uniq)
    assert (slots >= 0).all()
    np.testing.assert_array_equal(vm.coords[slots], uniq)
    w = np.bincount(inv, weights=a)  # eq. 8
    np.testing.assert_allclose(vm.weights[slots], w, rtol=1e-9)
    for k in range(3):  # eq. 7
        np.testing.assert_allclose(vm.colors[slots, k], np.bincount(inv, weights=a * col[:, k]) / w, atol=2e-3)
    fd = np.stack([np.bincount(inv, weights=a * feat[:, k]) / w for k in range(8)], axis=1)  # eq. 6
    np.testing.assert_allclose(vm.features[slots], fd, atol=1e-4)


def test_first_observation_is_stored_unbiased() -> None:
    vm = VoxelMap(0.05, feature_dim=2)
    vm.integrate(np.array([[0.01, 0.01, 0.01]]), np.array([0.3]), np.array([[10, 20, 30]], np.uint8),
                 np.array([0]), np.array([[2.0, -4.0]], np.float32))
    np.testing.assert_allclose(vm.features[0], [2.0, -4.0])
    np.testing.assert_allclose(vm.colors[0], [10, 20, 30])
    assert vm.weights[0] == pytest.approx(0.3)


def test_query_and_projection() -> None:
    rng = np.random.default_rng(0)
    P = random_projection(64, 16, seed=1)
    assert P.shape == (64, 16)
    np.testing.assert_allclose(P.T @ P, np.eye(16) * 4.0, atol=1e-5)
    vm = VoxelMap(0.1, feature_dim=16, projection=P, text_space="x")
    a, b = rng.standard_normal(64), rng.standard_normal(64)
    phi = vm.project(np.stack([a, b]).astype(np.float32))
    vm.integrate(np.array([[0.05, 0.05, 0.05], [1.05, 0.05, 0.05]]), np.ones(2), np.zeros((2, 3), np.uint8),
                 np.array([0, 1]), phi)
    s = vm.query(a)
    assert s[0] == pytest.approx(1.0, abs=1e-5) and s[1] < 0.6
    grid = GridSpec(0.0, 0.0, 0.1, 2, 12)
    top = vm.topdown_scores(a, grid)
    assert top[0, 0] == pytest.approx(1.0, abs=1e-5) and top[0, 10] == pytest.approx(s[1])
    assert top[1, 5] == -1.0  # unobserved cells get the lowest cosine
    with pytest.raises(InputError):
        vm.query(np.ones(10))


def test_occupancy_bands() -> None:
    vm = VoxelMap(0.05, feature_dim=1)
    floor = np.array([[x, 0.02, 0.01] for x in np.arange(0.0, 1.0, 0.05)])
    wall = np.array([[0.52, 0.02, z] for z in (0.3, 1.0)])
    ceiling = np.array([[0.77, 0.02, 2.4]])
    pts = np.concatenate([floor, wall, ceiling])
    vm.integrate(pts, np.ones(len(pts)), np.zeros((len(pts), 3), np.uint8), np.zeros(len(pts), int),
                 np.zeros((1, 1), np.float32))
    grid = GridSpec(0.0, 0.0, 0.05, 2, 20)
    occ = occupancy_from_voxels(vm, OccupancyConfig(), spec=grid)
    assert occ.cells[0, 10] == OCCUPIED  # wall over floor
    assert occ.cells[0, 15] == FREE  # ceiling is above the band: floor stays free
    assert occ.cells[0, 2] == FREE
    assert (occ.cells[1] == UNKNOWN).all()
    assert occ.inflated(0.1).cells[0, 12] == OCCUPIED


def test_whole_frame_kernel_equals_point_fusion() -> None:
    from capnav.core.geometry import Intrinsics, backproject, look_at_pose

    rng = np.random.default_rng(5)
    K = Intrinsics.from_fov(40, 30, 60.0)
    T = look_at_pose(np.array([0.3, -0.2, 1.2]), yaw=0.7, pitch=0.3)
    depth = rng.uniform(0.5, 4.0, (30, 40)).astype(np.float32)
    depth[0, :5] = 0.0
    depth[3, 3] = np.nan
    depth[4, 4] = np.inf
    depth[5, 5] = 9.0  # beyond max_depth
    rgb = rng.integers(0, 256, (30, 40, 3)).astype(np.uint8)
    grid = rng.integers(0, 7, (8, 10))
    table = rng.standard_normal((7, 4)).astype(np.float32)
    a = VoxelMap(0.1, (0.0, 0.0, 0.0), feature_dim=4)
    a.integrate_frame(depth, rgb, K, T, grid, table, sigma=2.0, max_depth=8.0, stride=2)
    keep = np.zeros((30, 40), bool)
    keep[::2, ::2] = True
    pc, flat = backproject(np.where(depth <= 8.0, depth, 0), K, None, keep)
    v, u = np.divmod(flat, 40)
    pw = pc.astype(np.float64) @ T[:3, :3].T + T[:3, 3]
    b = VoxelMap(0.1, (0.0, 0.0, 0.0), feature_dim=4)
    b.integrate(pw, radial_weight(pc, 2.0), rgb.reshape(-1, 3)[flat], grid[v * 8 // 30, u * 10 // 40].ravel(), table)
    assert len(a) == len(b) and len(a) > 100
    s = b.slots(a.coords)
    np.testing.assert_array_equal(s, np.arange(len(a)))
    np.testing.assert_allclose(a.weights, b.weights, rtol=1e-5)
    np.testing.assert_allclose(a.features, b.features, atol=1e-4)
    np.testing.assert_allclose(a.colors, b.colors, atol=1e-2)
    with pytest.raises(InputError, match="feature grid"):
        a.integrate_frame(depth, rgb, K, T, grid + 7, table, sigma=2.0)


def _sequential_fusion(pts: np.ndarray, alpha: np.ndarray, col: np.ndarray, fidx: np.ndarray, phi: np.ndarray,
                       res: float, origin: tuple[float, float, float]
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Eq. 4-8 one point at a time in plain numpy scalars: the arithmetic the kernels must reproduce
    to the bit (float64 weights, float32 ratio, colour and feature)."""
    ijk = np.floor((pts - np.asarray(origin)) / res).astype(np.int64)
    slot: dict[tuple[int, ...], int] = {}
    w: list[float] = []
    c: list[np.ndarray] = []
    f: list[np.ndarray] = []
    for p in range(len(pts)):
        s = slot.setdefault(tuple(ijk[p].tolist()), len(slot))
        if s == len(w):
            w.append(0.0)
            c.append(np.zeros(3, np.float32))
            f.append(np.zeros(phi.shape[1], np.float32))
        a = float(np.float64(alpha[p]))
        w_new = w[s] + a
        r = np.float32(a / w_new)
        c[s] = c[s] + r * (col[p].astype(np.float32) - c[s])
        f[s] = f[s] + r * (phi[fidx[p]] - f[s])
        w[s] = w_new
    order = sorted(slot, key=slot.__getitem__)
    return np.array(order, np.int32), np.array(w), np.array(c), np.array(f)


@pytest.mark.parametrize("dim", [1, 5])
def test_fusion_is_bit_identical_to_sequential_eq_6_8(dim: int) -> None:
    """The speed work (recent-voxel cache, per-voxel runs in registers, growth with resume) must
    not change a single bit of the result: runs of points in one voxel, revisits after other
    voxels, and enough new voxels to grow a tiny map several times."""
    rng = np.random.default_rng(11)
    res, origin = 0.1, (0.0, 0.0, -0.05)
    base = rng.uniform(-1.0, 1.0, (400, 3))
    pts = np.repeat(base, rng.integers(1, 9, len(base)), axis=0)  # runs of one voxel
    pts = np.concatenate([pts, pts[rng.permutation(len(pts))[:500]]]) + rng.normal(0, 0.01, (len(pts) + 500, 3))
    n = len(pts)
    alpha = rng.uniform(0.05, 1.0, n).astype(np.float32)
    col = rng.integers(0, 256, (n, 3)).astype(np.uint8)
    phi = rng.standard_normal((9, dim)).astype(np.float32)
    fidx = rng.integers(0, 9, n)
    vm = VoxelMap(res, origin, feature_dim=dim, capacity=16)
    half = n // 2
    vm.integrate(pts[:half], alpha[:half], col[:half], fidx[:half], phi)
    vm.integrate(pts[half:], alpha[half:], col[half:], fidx[half:], phi)
    coords, w, c, f = _sequential_fusion(pts, alpha, col, fidx, phi, res, origin)
    assert len(vm) == len(coords) > 300
    np.testing.assert_array_equal(vm.coords, coords)
    assert vm.weights.tobytes() == w.tobytes()
    assert vm.colors.tobytes() == c.astype(np.float32).tobytes()
    assert vm.features.tobytes() == f.astype(np.float32).tobytes()


def test_frame_kernel_is_bit_identical_to_sequential_eq_2_8() -> None:
    import math

    from capnav.core.geometry import Intrinsics, look_at_pose

    rng = np.random.default_rng(6)
    K = Intrinsics.from_fov(40, 30, 60.0)
    T = look_at_pose(np.array([0.3, -0.2, 1.2]), yaw=0.7, pitch=0.3)
    depth = np.repeat(rng.uniform(0.5, 4.0, (30, 8)), 5, axis=1).astype(np.float32)  # runs along rows
    depth[2, :7] = 0.0
    depth[3, 3] = np.nan
    rgb = rng.integers(0, 256, (30, 40, 3)).astype(np.uint8)
    grid = rng.integers(0, 7, (8, 10))
    table = rng.standard_normal((7, 4)).astype(np.float32)
    vm = VoxelMap(0.1, (0.0, 0.0, -0.05), feature_dim=4)
    vm.integrate_frame(depth, rgb, K, T, grid, table, sigma=2.0, max_depth=3.5)
    pts, alpha, col, fidx = [], [], [], []
    for v in range(30):
        for u in range(40):
            z = float(depth[v, u])
            if not (0.0 < z <= 3.5):
                continue
            x = (u - K.cx) * z / K.fx
            y = (v - K.cy) * z / K.fy
            alpha.append(math.exp(-(x * x + y * y + z * z) * (1.0 / (2.0 * 2.0 * 2.0))))
            pts.append([T[r, 0] * x + T[r, 1] * y + T[r, 2] * z + T[r, 3] for r in range(3)])
            col.append(rgb[v, u])
            fidx.append(grid[v * 8 // 30, u * 10 // 40])
    coords, w, c, f = _sequential_fusion(np.array(pts), np.array(alpha), np.array(col), np.array(fidx), table,
                                         0.1, (0.0, 0.0, -0.05))
    assert len(vm) == len(coords) > 50
    np.testing.assert_array_equal(vm.coords, coords)
    assert vm.weights.tobytes() == w.tobytes()
    assert vm.colors.tobytes() == c.astype(np.float32).tobytes()
    assert vm.features.tobytes() == f.astype(np.float32).tobytes()
