"""One object, one map entry: detections of one thing merged in the frame, duplicates at export."""

from __future__ import annotations

import numpy as np
import pytest
from _synth_scene import Box, render

from capnav.core.categories import category
from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.mapping import Mapper, MapperConfig
from capnav.mapping.frame_merge import FrameMergeConfig, merge_frame_detections
from capnav.mapping.memory import MemoryConfig
from capnav.perception import Detection, Detector, box_from_mask, create_detector, create_encoder


def _mask(r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
    m = np.zeros((60, 80), dtype=bool)
    m[r0:r1, c0:c1] = True
    return m


def _d(mask: np.ndarray, label: str, score: float) -> Detection:
    return Detection(box_from_mask(mask), category(label).id, label, score, mask)


def test_part_and_second_label_merge_but_a_chair_at_a_table_does_not() -> None:
    chair = _d(_mask(10, 50, 10, 30), "chair", 0.8)
    armrest = _d(_mask(30, 38, 10, 16), "chair", 0.5)  # a part box inside the whole
    as_toilet = _d(_mask(11, 50, 10, 30), "toilet", 0.6)  # the same pixels under another label
    table = _d(_mask(20, 55, 25, 75), "table", 0.9)
    seat = _d(_mask(25, 40, 40, 55), "chair", 0.7)  # a chair at the table: inside its mask, another thing
    out, n = merge_frame_detections([armrest, table, chair, seat, as_toilet])
    assert n == 2 and len(out) == 3
    merged = next(d for d in out if d.label_votes().keys() >= {"chair", "toilet"})
    assert merged.label == "chair" and merged.score == pytest.approx(0.8)
    assert merged.label_votes() == pytest.approx({"chair": 1.3, "toilet": 0.6})
    assert merged.area == (chair.mask | as_toilet.mask | armrest.mask).sum()
    assert {d.label for d in out} == {"chair", "table"} and seat in out and table in out
    kept, n0 = merge_frame_detections([chair, as_toilet], FrameMergeConfig(enabled=False))
    assert n0 == 0 and len(kept) == 2
    with pytest.raises(InputError):
        FrameMergeConfig(same_iou=0.0)


class _TwiceDetector(Detector):
    """A real detector's failure, made from the oracle: every object also reported as 'toilet'
    (a second label for the same pixels) and its upper half as a part box of its own."""

    def __init__(self) -> None:
        self.inner = create_detector("sim", noise="oracle", seed=0)
        self.id = "twice"

    def detect(self, frame: Frame) -> list[Detection]:
        out = []
        for d in self.inner.detect(frame):
            rows = np.flatnonzero(d.mask.any(axis=1))
            part = d.mask.copy()
            part[rows[len(rows) // 2]:] = False
            out += [d, Detection(d.box, category("toilet").id, "toilet", 0.6, d.mask.copy()),
                    Detection(box_from_mask(part), d.class_id, d.label, 0.5, part)]
        return out


def _map(embedder, detector: Detector, **cfg) -> list:  # type: ignore[no-untyped-def]
    boxes = [Box((1.0, -1.0, 0.0), (1.5, -0.5, 0.9), 1, 3, (200, 0, 0)),
             Box((1.0, 0.3, 0.0), (1.8, 1.2, 0.75), 2, 5, (0, 0, 200))]
    K = Intrinsics.from_fov(160, 120, 60.0)
    m = Mapper(MapperConfig(**cfg), detector, create_encoder("label-embedding", embedder=embedder))
    for i in range(10):
        m.integrate(render(boxes, look_at_pose(np.array([-1.0, 0.0, 1.2]), yaw=0.02 * i, pitch=np.deg2rad(25)),
                           K, index=i))
    return m.finish().objects


def test_one_object_per_thing_in_the_map(embedder) -> None:  # type: ignore[no-untyped-def]
    truth = _map(embedder, create_detector("sim", noise="oracle", seed=0))
    assert sorted(o.label for o in truth) == ["chair", "table"]
    for kw in ({}, {"frame_merge": FrameMergeConfig(enabled=False)}):  # in the frame, or else at export
        objs = _map(embedder, _TwiceDetector(), **kw)
        assert sorted(o.label for o in objs) == ["chair", "table"], kw
        assert all(set(o.label_votes) == {o.label, "toilet"} for o in objs)
    off = _map(embedder, _TwiceDetector(), frame_merge=FrameMergeConfig(enabled=False),
               memory=MemoryConfig(same_overlap=1.1))
    assert len(off) > 2  # neither merge: the duplicates stay
