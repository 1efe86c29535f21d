"""A box detector for tests: boxes from the truth images, masks from depth as the COCO detectors
make them (only the box reaches the mapper, never the instance mask)."""

from __future__ import annotations

import numpy as np

from capnav.core.categories import BY_NAME
from capnav.core.frame import Frame
from capnav.perception import Detection, Detector
from capnav.perception.box_masks import depth_box_masks, floor_pixels, up_facing_pixels


class TrueBoxDetector(Detector):
    """Boxes from the truth images (grown by ``grow`` each side), masks from depth as the COCO detectors make them:
    only the box reaches the mapper, never the instance mask. Things score higher than furniture
    (a cup is easy, a table half hidden under its things is not)."""

    id = "test:true-boxes"
    needs_truth = True

    def __init__(self, labels: dict[int, str], grow: float = 0.025, pieces: bool = True) -> None:
        self.labels = labels
        self.grow = grow  # each side, as a share of the box
        self.pieces = pieces  # keep the masks' pieces that make one thing in 3D (box_pieces)

    def detect(self, frame: Frame) -> list[Detection]:
        assert frame.gt_instance is not None
        inst = np.asarray(frame.gt_instance)
        h, w = inst.shape
        boxes, names = [], []
        for iid, name in self.labels.items():
            vs, us = np.nonzero(inst == iid)
            if vs.size < 30:
                continue
            gx, gy = self.grow * (us.max() - us.min() + 1), self.grow * (vs.max() - vs.min() + 1)
            boxes.append((max(0.0, us.min() - gx), max(0.0, vs.min() - gy), min(float(w), us.max() + 1 + gx),
                          min(float(h), vs.max() + 1 + gy)))
            names.append(name)
        floor = floor_pixels(frame.depth, frame.K, frame.T_wc, 0.05)
        out = []
        up = up_facing_pixels(frame.depth, frame.K, frame.T_wc)
        masks = depth_box_masks(frame.depth, boxes, exclude=floor, up=up, K=frame.K if self.pieces else None)
        for b, name, m in zip(boxes, names, masks, strict=True):
            if m.sum() < 10:
                continue
            cat = BY_NAME.get(name)
            out.append(Detection(b, cat.id if cat else 0, name, 0.5 if cat else 0.9, m))
        return out
