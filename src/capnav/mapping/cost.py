"""The association cost of paper eq. 12 and its gates (Algorithm 1, step 2)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def box_iou(a: NDArray[np.floating], b: NDArray[np.floating]) -> NDArray[np.float64]:
    """Pairwise IoU of xyxy boxes (T, 4) x (N, 4) -> (T, N)."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    b = np.asarray(b, dtype=np.float64).reshape(-1, 4)
    ix = np.clip(np.minimum(a[:, None, 2], b[None, :, 2]) - np.maximum(a[:, None, 0], b[None, :, 0]), 0, None)
    iy = np.clip(np.minimum(a[:, None, 3], b[None, :, 3]) - np.maximum(a[:, None, 1], b[None, :, 1]), 0, None)
    inter = ix * iy
    area_a = np.clip(a[:, 2] - a[:, 0], 0, None) * np.clip(a[:, 3] - a[:, 1], 0, None)
    area_b = np.clip(b[:, 2] - b[:, 0], 0, None) * np.clip(b[:, 3] - b[:, 1], 0, None)
    union = area_a[:, None] + area_b[None, :] - inter
    return np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)


def cosine(a: NDArray[np.floating], b: NDArray[np.floating]) -> NDArray[np.float64]:
    """Pairwise cosine similarity (T, D) x (N, D) -> (T, N); zero vectors give 0."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    na = np.linalg.norm(a, axis=1, keepdims=True)
    nb = np.linalg.norm(b, axis=1, keepdims=True)
    return (a / np.maximum(na, 1e-12)) @ (b / np.maximum(nb, 1e-12)).T


def association_cost(pred: NDArray[np.floating], track_boxes: NDArray[np.floating],
                     track_feats: NDArray[np.floating], track_cls: NDArray[np.integer],
                     det_pos: NDArray[np.floating], det_boxes: NDArray[np.floating],
                     det_feats: NDArray[np.floating], det_cls: NDArray[np.integer],
                     weights: tuple[float, float, float, float], d_max: float, tau_assoc: float
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Eq. 12 for every (track j, detection i) pair, then the gates of Algorithm 1.

    ``C = a3d * ||p_pred - x|| / d_max + b2d * (1 - IoU) + g_sem * (1 - cos) + l_cls * [c_j != c_i]``;
    pairs with distance > d_max or C > tau_assoc become +inf. Returns (gated C, raw C).
    """
    a3d, b2d, g_sem, l_cls = weights
    dist = np.linalg.norm(np.asarray(pred, dtype=np.float64)[:, None, :] - np.asarray(det_pos)[None, :, :], axis=2)
    iou = box_iou(track_boxes, det_boxes)
    cos = cosine(track_feats, det_feats)
    cls = (np.asarray(track_cls)[:, None] != np.asarray(det_cls)[None, :]).astype(np.float64)
    raw = a3d * dist / d_max + b2d * (1.0 - iou) + g_sem * (1.0 - cos) + l_cls * cls
    gated = np.where((dist > d_max) | (raw > tau_assoc), np.inf, raw)
    return gated, raw
