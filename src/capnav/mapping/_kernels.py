"""Numba kernels of the sparse voxel map: an open-addressing hash from voxel key to slot, and the
per-point running weighted averages of eq. 6-8 (numpy has no vectorised "update this slot in
place, in order" primitive; a sort-and-reduce per frame is 5-10x slower)."""

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


@nb.njit(cache=True, nogil=True)
def fuse(table_keys: NDArray[np.int64], table_vals: NDArray[np.int32], shift: np.uint64,
         voxel_keys: NDArray[np.int64], weights: NDArray[np.float64], colors: NDArray[np.float32],
         features: NDArray[np.float32], n: int, keys: NDArray[np.int64], alpha: NDArray[np.float32],
         point_colors: NDArray[np.uint8], feat_index: NDArray[np.int64], phi: NDArray[np.float32]) -> int:
    """Apply eq. 6-8 for every point in order; returns the new voxel count.

    Capacity of the table (< 50% load after this call) and of the voxel arrays is ensured by the
    caller. ``f += a / (w + a) * (f_t - f)`` is eq. 6 rearranged; a new voxel starts at w = 0 so
    its first value is exactly the first observation (no ``f * alpha`` bias).
    """
    d = features.shape[1]
    for p in range(keys.shape[0]):
        s, n = _claim(table_keys, table_vals, shift, voxel_keys, weights, colors, features, n, keys[p])
        a = np.float64(alpha[p])
        w_new = weights[s] + a
        r = np.float32(a / w_new)
        for c in range(3):
            colors[s, c] += r * (np.float32(point_colors[p, c]) - colors[s, c])
        fi = feat_index[p]
        for j in range(d):
            features[s, j] += r * (phi[fi, j] - features[s, j])
        weights[s] = w_new
    return n


@nb.njit(cache=True, nogil=True)
def fuse_image(table_keys: NDArray[np.int64], table_vals: NDArray[np.int32], shift: np.uint64,
               voxel_keys: NDArray[np.int64], weights: NDArray[np.float64], colors: NDArray[np.float32],
               features: NDArray[np.float32], n: int, depth: NDArray[np.float32], rgb: NDArray[np.uint8],
               intr: NDArray[np.float64], T: NDArray[np.float64], origin: NDArray[np.float64], res: float,
               sigma: float, max_depth: float, stride: int, cell_rows: int, cell_cols: int,
               feat_grid: NDArray[np.int64], phi: NDArray[np.float32]) -> int:
    """Eq. 2-8 for every ``stride``-th valid pixel of one frame, in row-major order, without
    temporaries: back-project (eq. 2-3), weight (eq. 5), index (eq. 4), fuse (eq. 6-8).
    Pixel (u, v) takes feature row ``feat_grid[v * cell_rows // H, u * cell_cols // W]``."""
    h, w = depth.shape
    fx, fy, cx, cy = intr[0], intr[1], intr[2], intr[3]
    inv2s2 = 1.0 / (2.0 * sigma * sigma)
    d = features.shape[1]
    off = np.int64(1 << 20)
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
            s, n = _claim(table_keys, table_vals, shift, voxel_keys, weights, colors, features, n, key)
            w_new = weights[s] + a
            r = np.float32(a / w_new)
            for c in range(3):
                colors[s, c] += r * (np.float32(rgb[v, u, c]) - colors[s, c])
            fi = feat_grid[v * cell_rows // h, u * cell_cols // w]
            for jj in range(d):
                features[s, jj] += r * (phi[fi, jj] - features[s, jj])
            weights[s] = w_new
    return n
