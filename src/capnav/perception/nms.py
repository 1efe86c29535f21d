"""Non-maximum suppression in numpy, shared by the detectors (one greedy pass; per class by
shifting each class's boxes far from the others')."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError


def nms(boxes: NDArray[np.floating], scores: NDArray[np.floating], iou_threshold: float) -> NDArray[np.int64]:
    """Greedy non-maximum suppression; indices of the kept boxes, best score first.

    Ties in score keep the lower index first (stable sort), so the result is deterministic.
    """
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    s = np.asarray(scores, dtype=np.float64).ravel()
    if b.shape[0] != s.shape[0]:
        raise InputError(f"nms got {b.shape[0]} boxes but {s.shape[0]} scores")
    order = np.argsort(-s, kind="stable")
    area = np.clip(b[:, 2] - b[:, 0], 0, None) * np.clip(b[:, 3] - b[:, 1], 0, None)
    keep: list[int] = []
    while order.size:
        i = int(order[0])
        keep.append(i)
        rest = order[1:]
        iw = np.clip(np.minimum(b[i, 2], b[rest, 2]) - np.maximum(b[i, 0], b[rest, 0]), 0, None)
        ih = np.clip(np.minimum(b[i, 3], b[rest, 3]) - np.maximum(b[i, 1], b[rest, 1]), 0, None)
        inter = iw * ih
        union = area[i] + area[rest] - inter
        iou = np.where(union > 0, inter / np.where(union > 0, union, 1.0), 0.0)
        order = rest[iou <= iou_threshold]
    return np.array(keep, dtype=np.int64)


def per_class_nms(boxes: NDArray[np.floating], scores: NDArray[np.floating], classes: NDArray[np.integer],
                  iou_threshold: float) -> NDArray[np.int64]:
    """Per-class NMS in numpy: each class's boxes are shifted far from the others', so one greedy
    NMS never lets two classes suppress each other. Kept indices, best score first."""
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    if b.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    span = float(np.abs(b).max()) + 1.0
    shifted = b + (np.asarray(classes, dtype=np.float64).ravel() * 2.0 * span)[:, None]
    return nms(shifted, scores, iou_threshold)
