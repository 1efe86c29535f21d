"""Numba kernels of the sparse voxel map: an open-addressing hash from voxel key to slot, and the
per-point running weighted averages of eq. 6-8 (numpy has no vectorised "update this slot in
place, in order" primitive; a sort-and-reduce per frame is 5-10x slower).

Speed comes from locality, not from changing the arithmetic: neighbouring pixels fall into the
same or a recently seen voxel, so a small direct-mapped cache of recent key -> slot pairs answers
most look-ups without touching the (large, randomly addressed) hash table, and each voxel's
feature row is updated with one vectorisable loop. The floating-point operations and their order
per voxel are exactly those of eq. 6-8 applied point by point, so results are bit-identical to a
plain sequential loop (tests/mapping/test_voxel_map.py pins that)."""

from __future__ import annotations

import numba as nb
import numpy as np
from numpy.typing import NDArray

EMPTY = np.int64(-1)
OFFSET = 1 << 20  # voxel indices in [-2^20, 2^20) (52 km at 5 cm) are packed into 21 bits each
_MULT = np.uint64(0x9E3779B97F4A7C15)


def pack_keys(ijk: NDArray[np.integer]) -> NDArray[np.int64]:
    """(N, 3) voxel indices -> (N,) non-negative int64 keys."""
    a = np.asarray(ijk, dtype=np.int64) + OFFSET
    return (a[:, 0] << 42) | (a[:, 1] << 21) | a[:, 2]


def unpack_keys(keys: NDArray[np.int64]) -> NDArray[np.int32]:
    mask = (1 << 21) - 1
    out = np.stack([(keys >> 42) & mask, (keys >> 21) & mask, keys & mask], axis=1) - OFFSET
    return out.astype(np.int32)


@nb.njit(cache=True, nogil=True)
def _slot_of(table_keys: NDArray[np.int64], key: np.int64, shift: np.uint64) -> np.int64:
    cap_mask = table_keys.shape[0] - 1
    h = np.int64((np.uint64(key) * _MULT) >> shift)
    while True:
        k = table_keys[h]
        if k == key or k == -1:
            return h
        h = (h + 1) & cap_mask


@nb.njit(cache=True, nogil=True)
def rehash(voxel_keys: NDArray[np.int64], n: int, capacity: int, shift: np.uint64
           ) -> tuple[NDArray[np.int64], NDArray[np.int32]]:
    tk = np.full(capacity, -1, dtype=np.int64)
    tv = np.zeros(capacity, dtype=np.int32)
    for s in range(n):
        h = _slot_of(tk, voxel_keys[s], shift)
        tk[h] = voxel_keys[s]
        tv[h] = s
    return tk, tv


@nb.njit(cache=True, nogil=True)
def lookup(table_keys: NDArray[np.int64], table_vals: NDArray[np.int32], keys: NDArray[np.int64],
           shift: np.uint64) -> NDArray[np.int64]:
    """Slot of each key, -1 if absent."""
    out = np.empty(keys.shape[0], dtype=np.int64)
    for p in range(keys.shape[0]):
        h = _slot_of(table_keys, keys[p], shift)
        out[p] = table_vals[h] if table_keys[h] == keys[p] else -1
    return out


@nb.njit(cache=True, nogil=True)
def _claim(table_keys: NDArray[np.int64], table_vals: NDArray[np.int32], shift: np.uint64,
           voxel_keys: NDArray[np.int64], weights: NDArray[np.float64], colors: NDArray[np.float32],
           features: NDArray[np.float32], n: int, key: np.int64) -> tuple[int, int]:
    """The slot of voxel ``key`` and the new voxel count: an unseen key gets slot ``n`` with zero
    weight, colour and feature, so its first update is exactly its first observation."""
    h = _slot_of(table_keys, key, shift)
    if table_keys[h] != -1:
        return int(table_vals[h]), n
    table_keys[h] = key
    table_vals[h] = n
    voxel_keys[n] = key
    weights[n] = 0.0
    colors[n, :] = 0.0
    features[n, :] = 0.0
    return n, n + 1


#: Entries of the recent-voxel cache: 65536 (768 KiB) keeps ~95% of look-ups of an apartment's
#: frames off the hash table (4096 entries: ~88%), as the cache lives as long as the map.
CACHE_BITS = 16


def new_cache() -> tuple[NDArray[np.int64], NDArray[np.int32]]:
    """An empty recent-voxel cache (keys -1)."""
    return np.full(1 << CACHE_BITS, -1, dtype=np.int64), np.zeros(1 << CACHE_BITS, dtype=np.int32)


@nb.njit(cache=True, nogil=True, inline="always")
def _cache_index(key: np.int64) -> np.int64:
    return np.int64((np.uint64(key) * _MULT) >> np.uint64(64 - CACHE_BITS))


@nb.njit(cache=True, nogil=True, inline="always")
def _slot_cached(cache_k: NDArray[np.int64], cache_s: NDArray[np.int32], table_keys: NDArray[np.int64],
                 table_vals: NDArray[np.int32], shift: np.uint64, voxel_keys: NDArray[np.int64],
                 weights: NDArray[np.float64], colors: NDArray[np.float32], features: NDArray[np.float32],
                 n: int, key: np.int64) -> tuple[int, int]:
    """``_claim`` behind the recent-voxel cache (slots never move, so entries never go stale)."""
    ci = _cache_index(key)
    if cache_k[ci] == key:
        return int(cache_s[ci]), n
    s, n = _claim(table_keys, table_vals, shift, voxel_keys, weights, colors, features, n, key)
    cache_k[ci] = key
    cache_s[ci] = np.int32(s)
    return s, n


@nb.njit(cache=True, nogil=True, inline="always")
def _feature_step(features: NDArray[np.float32], s: int, r: np.float32, phi: NDArray[np.float32], fi: np.int64
                  ) -> None:
    """Eq. 6 for one point: ``f += r * (f_t - f)`` over the feature row (vectorised by LLVM)."""
    for j in range(features.shape[1]):
        features[s, j] += r * (phi[fi, j] - features[s, j])


@nb.njit(cache=True, nogil=True)
def fuse_points(cache_k: NDArray[np.int64], cache_s: NDArray[np.int32],
                table_keys: NDArray[np.int64], table_vals: NDArray[np.int32], shift: np.uint64,
                voxel_keys: NDArray[np.int64], weights: NDArray[np.float64], colors: NDArray[np.float32],
                features: NDArray[np.float32], n: int, points: NDArray[np.float64], origin: NDArray[np.float64],
                res: float, alpha: NDArray[np.float32], point_colors: NDArray[np.uint8],
                feat_index: NDArray[np.int64], phi: NDArray[np.float32], start: int, limit: int
                ) -> tuple[int, int]:
    """Eq. 4 (``floor((p - origin) / res)``, as ``VoxelMap.index_of``) and eq. 6-8 for the world
    points from ``start`` on, in order, in one pass without temporaries.

    ``x += a / (w + a) * (x_t - x)`` is eq. 6-7 rearranged (r = a / (w + a) rounded to float32),
    ``w += a`` eq. 8; a new voxel starts at w = 0 so its first value is exactly the first
    observation (no ``f * alpha`` bias). While consecutive points stay in one voxel its weight and
    colour live in registers (written back when the voxel changes): the same operations in the
    same order, without a store-to-load round trip per point.

    Stops before the voxel count could exceed ``limit`` (the caller's capacity of the voxel arrays
    and of the table at < 50% load) and returns (voxel count, first point not fused) so the caller
    grows and resumes: growing with the voxels seen, not one voxel per point, keeps the table small.
    """
    off = np.int64(1 << 20)
    o0, o1, o2 = origin[0], origin[1], origin[2]
    cur = np.int64(-1)
    s = 0
    cw = 0.0
    c0 = c1 = c2 = np.float32(0.0)
    for p in range(start, points.shape[0]):
        i = np.int64(np.floor((points[p, 0] - o0) / res)) + off
        j = np.int64(np.floor((points[p, 1] - o1) / res)) + off
        k = np.int64(np.floor((points[p, 2] - o2) / res)) + off
        key = (i << 42) | (j << 21) | k
        if key != cur:
            if cur >= 0:
                weights[s], colors[s, 0], colors[s, 1], colors[s, 2] = cw, c0, c1, c2
            if n >= limit:
                return n, p
            s, n = _slot_cached(cache_k, cache_s, table_keys, table_vals, shift, voxel_keys, weights, colors,
                                features, n, key)
            cur = key
            cw, c0, c1, c2 = weights[s], colors[s, 0], colors[s, 1], colors[s, 2]
        a = np.float64(alpha[p])
        cw += a
        r = np.float32(a / cw)
        c0 += r * (np.float32(point_colors[p, 0]) - c0)
        c1 += r * (np.float32(point_colors[p, 1]) - c1)
        c2 += r * (np.float32(point_colors[p, 2]) - c2)
        _feature_step(features, s, r, phi, feat_index[p])
    if cur >= 0:
        weights[s], colors[s, 0], colors[s, 1], colors[s, 2] = cw, c0, c1, c2
    return n, points.shape[0]


@nb.njit(cache=True, nogil=True)
def fuse_image(cache_k: NDArray[np.int64], cache_s: NDArray[np.int32],
               table_keys: NDArray[np.int64], table_vals: NDArray[np.int32], shift: np.uint64,
               voxel_keys: NDArray[np.int64], weights: NDArray[np.float64], colors: NDArray[np.float32],
               features: NDArray[np.float32], n: int, depth: NDArray[np.float32], rgb: NDArray[np.uint8],
               intr: NDArray[np.float64], T: NDArray[np.float64], origin: NDArray[np.float64], res: float,
               sigma: float, max_depth: float, stride: int, cell_rows: int, cell_cols: int,
               feat_grid: NDArray[np.int64], phi: NDArray[np.float32]) -> int:
    """Eq. 2-8 for every ``stride``-th valid pixel of one frame, in row-major order, without
    temporaries: back-project (eq. 2-3), weight (eq. 5), index (eq. 4), fuse (eq. 6-8) exactly as
    ``fuse_points`` (capacity for one voxel per pixel is ensured by the caller).
    Pixel (u, v) takes feature row ``feat_grid[v * cell_rows // H, u * cell_cols // W]``."""
    h, w = depth.shape
    fx, fy, cx, cy = intr[0], intr[1], intr[2], intr[3]
    inv2s2 = 1.0 / (2.0 * sigma * sigma)
    off = np.int64(1 << 20)
    cur = np.int64(-1)
    s = 0
    cw = 0.0
    c0 = c1 = c2 = np.float32(0.0)
    for v in range(0, h, stride):
        for u in range(0, w, stride):
            z = np.float64(depth[v, u])
            if not (z > 0.0 and z <= max_depth):  # also rejects NaN
                continue
            x = (u - cx) * z / fx
            y = (v - cy) * z / fy
            a = np.exp(-(x * x + y * y + z * z) * inv2s2)
            wx = T[0, 0] * x + T[0, 1] * y + T[0, 2] * z + T[0, 3]
            wy = T[1, 0] * x + T[1, 1] * y + T[1, 2] * z + T[1, 3]
            wz = T[2, 0] * x + T[2, 1] * y + T[2, 2] * z + T[2, 3]
            i = np.int64(np.floor((wx - origin[0]) / res)) + off
            j = np.int64(np.floor((wy - origin[1]) / res)) + off
            k = np.int64(np.floor((wz - origin[2]) / res)) + off
            key = (i << 42) | (j << 21) | k
            if key != cur:
                if cur >= 0:
                    weights[s], colors[s, 0], colors[s, 1], colors[s, 2] = cw, c0, c1, c2
                s, n = _slot_cached(cache_k, cache_s, table_keys, table_vals, shift, voxel_keys, weights, colors,
                                    features, n, key)
                cur = key
                cw, c0, c1, c2 = weights[s], colors[s, 0], colors[s, 1], colors[s, 2]
            cw += a
            r = np.float32(a / cw)
            c0 += r * (np.float32(rgb[v, u, 0]) - c0)
            c1 += r * (np.float32(rgb[v, u, 1]) - c1)
            c2 += r * (np.float32(rgb[v, u, 2]) - c2)
            _feature_step(features, s, r, phi, feat_grid[v * cell_rows // h, u * cell_cols // w])
    if cur >= 0:
        weights[s], colors[s, 0], colors[s, 1], colors[s, 2] = cw, c0, c1, c2
    return n
