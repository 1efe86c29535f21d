"""One physical object, one detection: overlapping detections of a frame merged before tracking.

A real detector reports one chair as the whole chair plus a part (an armrest box inside the
chair's box), or twice under two labels (chair and toilet); per-class NMS keeps both, and each
becomes a track and then a map object, so "the closest chair" may pick the duplicate. Masks tell
what pixels each claims: two detections are one thing when their masks overlap by IoU >=
``same_iou`` (any labels), or when the smaller mask lies at least ``part_inside`` inside the
larger one and the labels are equal or lookalikes (``capnav.core.categories.confusable``: a
chair's box inside a table's box is a chair at the table, not a part of it). The merged
detection keeps the larger mask united with the smaller, the union box, the best score and the
best-scoring label, and every label's score as ``votes`` for the tracker and the object memory.

Weak candidates (``Detection.weak``, below the detector's score threshold) are merged only with
each other, and one whose mask lies mostly (``weak_covered``) on the pixels of the frame's
confident detections is dropped: those pixels are explained, and a low-score second reading of
them (CenterNet's "bench" at 0.2 on the box of a chair at 0.5) is not another thing. For a
label with a shape prior (``corroborate.PRIORS``: its own points are checked before it can
confirm) only the confident detections whose box holds ``weak_box_inside`` of the weak box (a
second reading of that box) or is larger than it count there: a table's box mask lies for the most part on the masks of
the chairs at it (each chair's box holds a piece of the top, in the chair's depth band: 39-68% in
tests/mapping/test_weak_shape.py), yet none of those smaller boxes is the table's. For the other
labels every confident mask counts. (With the box rule alone, a weak "chair" on a confident bed's
mask became a second object on the bed: Sweet Home 3D seed 301, Yolo-Fastest.)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from capnav.core.categories import confusable
from capnav.core.errors import InputError
from capnav.mapping.corroborate import PRIORS
from capnav.perception.base import Detection, box_from_mask


@dataclass(frozen=True)
class FrameMergeConfig:
    """``same_iou``: mask IoU above which two detections are one thing whatever their labels;
    ``part_inside``: share of the smaller mask inside the larger above which it is a part of it
    (same or lookalike labels). ``enabled=False`` passes detections through."""

    enabled: bool = True
    same_iou: float = 0.6
    part_inside: float = 0.85
    weak_covered: float = 0.5
    weak_box_inside: float = 0.7  # labels with a shape prior; 0: every confident mask explains them (as before)

    def __post_init__(self) -> None:
        if not (0.0 < self.same_iou <= 1.0 and 0.0 < self.part_inside <= 1.0 and 0.0 < self.weak_covered <= 1.0):
            raise InputError("same_iou, part_inside and weak_covered must be in (0, 1]")


def _box_inside(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> float:
    """Share of box ``a``'s area inside box ``b``."""
    w = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    h = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    return w * h / max((a[2] - a[0]) * (a[3] - a[1]), 1e-9)


def _area(b: tuple[float, float, float, float]) -> float:
    return max(b[2] - b[0], 0.0) * max(b[3] - b[1], 0.0)


def _explained(weak: Detection, strong: Sequence[Detection], cfg: FrameMergeConfig) -> bool:
    """Whether ``weak``'s mask lies mostly on the masks of confident detections of its box."""
    own = weak.label in PRIORS
    same = [d.mask for d in strong if not own or _box_inside(weak.box, d.box) >= cfg.weak_box_inside
            or _area(d.box) >= _area(weak.box)]
    if not same:
        return False
    seen = np.logical_or.reduce(same)
    return int((weak.mask & seen).sum()) >= cfg.weak_covered * max(weak.area, 1)


def _related(a: str, b: str) -> bool:
    return a == b or b in confusable(a)


def merge_frame_detections(dets: Sequence[Detection], cfg: FrameMergeConfig | None = None
                           ) -> tuple[list[Detection], int]:
    """Merge the detections of one frame that show one thing; returns (detections, merges).
    Confident detections come first, then the weak candidates left (see the module docstring)."""
    cfg = cfg or FrameMergeConfig()
    strong, weak = [d for d in dets if not d.weak], [d for d in dets if d.weak]
    if not weak:
        return _merge(strong, cfg)
    out, merges = _merge(strong, cfg)
    if out:
        weak = [d for d in weak if not _explained(d, out, cfg)]
    kept, more = _merge(weak, cfg)
    return out + kept, merges + more


def _merge(dets: Sequence[Detection], cfg: FrameMergeConfig) -> tuple[list[Detection], int]:
    out = list(dets)
    if not cfg.enabled or len(out) < 2:
        return out, 0
    merges = 0
    changed = True
    while changed:
        changed = False
        order = sorted(range(len(out)), key=lambda k: -out[k].area)
        for ii, i in enumerate(order):
            for j in order[ii + 1:]:
                big, small = out[i], out[j]
                inter = int((big.mask & small.mask).sum())
                if inter == 0:
                    continue
                iou = inter / max(big.area + small.area - inter, 1)
                inside = inter / max(small.area, 1)
                if iou >= cfg.same_iou or (inside >= cfg.part_inside and _related(big.label, small.label)):
                    out[i] = _combine(big, small)
                    del out[j]
                    merges += 1
                    changed = True
                    break
            if changed:
                break
    return out, merges


def _combine(a: Detection, b: Detection) -> Detection:
    votes = a.label_votes()
    for k, v in b.label_votes().items():
        votes[k] = votes.get(k, 0.0) + v
    lead = a if a.score >= b.score else b
    mask = a.mask | b.mask
    box = box_from_mask(mask)
    ub = (min(a.box[0], b.box[0]), min(a.box[1], b.box[1]), max(a.box[2], b.box[2]), max(a.box[3], b.box[3]))
    return Detection(ub if np.all(np.isfinite(ub)) else box, lead.class_id, lead.label, max(a.score, b.score),
                     mask, votes, weak=a.weak and b.weak)
