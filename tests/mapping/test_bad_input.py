"""Bad frames give a named skip (default) or a FrameError (strict), never a silently wrong map."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _synth_scene import orbit

from capnav.core.errors import FrameError, PoseError
from capnav.mapping import Mapper, MapperConfig
from capnav.perception import Detection, Detector, create_detector, create_encoder


@pytest.fixture(scope="module")
def frames() -> list:
    return orbit(12)


def _mapper(embedder, strict: bool = False, detector: Detector | None = None) -> Mapper:  # type: ignore[no-untyped-def]
    cfg = MapperConfig(on_bad_frame="raise" if strict else "skip")
    return Mapper(cfg, detector or create_detector("sim", noise="oracle"),
                  create_encoder("label-embedding", embedder=embedder))


def test_nan_inf_and_zero_depth_are_masked(frames: list, embedder) -> None:  # type: ignore[no-untyped-def]
    clean = _mapper(embedder)
    dirty = _mapper(embedder)
    for f in frames:
        clean.integrate(f)
        d = f.depth.copy()
        d[::7, ::5] = np.nan
        d[1::7, ::5] = np.inf
        d[2::7, ::5] = 0.0
        d[3::7, ::5] = -1.0
        dirty.integrate(dataclasses.replace(f, depth=d))
    a, b = clean.finish(), dirty.finish()
    assert not b.meta["frames_skipped"]
    assert 0.8 * len(a.voxels) < len(b.voxels) <= len(a.voxels)
    assert np.isfinite(b.voxels.features).all() and np.isfinite(b.voxels.colors).all()
    assert np.isfinite(b.voxels.weights).all() and (b.voxels.weights > 0).all()
    assert [o.label for o in a.objects] == [o.label for o in b.objects]
    for oa, ob in zip(a.objects, b.objects, strict=True):
        assert np.isfinite(ob.points).all()
        assert np.linalg.norm(oa.position - ob.position) < 0.05


def test_bad_frames_are_skipped_and_named(frames: list, embedder) -> None:  # type: ignore[no-untyped-def]
    m = _mapper(embedder)
    f = frames[0]
    bad_pose = f.T_wc.copy()
    bad_pose[:3, :3] *= 1.5
    mirror = f.T_wc.copy()
    mirror[:3, 0] *= -1
    cases = [
        dataclasses.replace(f, index=100, depth=np.full_like(f.depth, np.nan)),
        dataclasses.replace(f, index=101, depth=f.depth[:-1]),
        dataclasses.replace(f, index=102, T_wc=bad_pose),
        dataclasses.replace(f, index=103, T_wc=mirror),
        dataclasses.replace(f, index=104, rgb=f.rgb[..., :2]),
        dataclasses.replace(f, index=105, gt_instance=f.gt_instance[:, :-3]),
    ]
    for c in cases:
        assert m.integrate(c) is False
    assert m.integrate(frames[1]) is True
    cmap = m.finish()
    skipped = {s["frame"]: s["reason"] for s in cmap.meta["frames_skipped"]}
    assert sorted(skipped) == [100, 101, 102, 103, 104, 105]
    assert "invalid" in skipped[100] and "depth shape" in skipped[101]
    assert "orthonormal" in skipped[102] and "det" in skipped[103]
    assert cmap.meta["frames_used"] == 1


def test_strict_mode_raises_naming_the_frame(frames: list, embedder) -> None:  # type: ignore[no-untyped-def]
    m = _mapper(embedder, strict=True)
    bad = frames[2].T_wc.copy()
    bad[0, 3] = np.nan
    with pytest.raises(PoseError, match="frame 2"):
        m.integrate(dataclasses.replace(frames[2], T_wc=bad))
    with pytest.raises(FrameError, match="frame 3: depth shape"):
        m.integrate(dataclasses.replace(frames[3], depth=frames[3].depth[:, 1:]))


class _Fixed(Detector):
    id = "fixed"

    def __init__(self, dets: list[Detection]) -> None:
        self.dets = dets

    def detect(self, frame):  # type: ignore[no-untyped-def]
        return self.dets


def test_empty_and_malformed_detections(frames: list, embedder) -> None:  # type: ignore[no-untyped-def]
    m = _mapper(embedder, detector=_Fixed([]))
    for f in frames[:4]:
        assert m.integrate(f)
    cmap = m.finish()
    assert cmap.objects == [] and len(cmap.voxels) > 1000  # geometry is still mapped
    wrong = Detection((0, 0, 5, 5), 3, "chair", 0.9, np.ones((10, 10), bool))
    m2 = _mapper(embedder, strict=True, detector=_Fixed([wrong]))
    with pytest.raises(FrameError, match="frame 0: detection 0 mask shape"):
        m2.integrate(frames[0])
    nanbox = Detection((0, 0, np.nan, 5), 3, "chair", 0.9, np.ones((120, 160), bool))
    with pytest.raises(FrameError, match="non-finite box"):
        _mapper(embedder, strict=True, detector=_Fixed([nanbox])).integrate(frames[0])
    # a detection whose mask has no valid depth is skipped and counted, not lifted to garbage
    f = frames[0]
    hole = np.zeros(f.depth.shape, bool)
    hole[10:20, 10:20] = True
    m3 = _mapper(embedder, detector=_Fixed([Detection((10, 10, 20, 20), 3, "chair", 0.9, hole)]))
    m3.integrate(dataclasses.replace(f, depth=np.where(hole, 0.0, f.depth).astype(np.float32)))
    assert m3.lift_skips == 1 and m3.finish().meta["detections_without_depth"] == 1


def test_pose_jumps_are_reported(frames: list, embedder) -> None:  # type: ignore[no-untyped-def]
    m = _mapper(embedder)
    m.integrate(frames[0])
    far = frames[1].T_wc.copy()
    far[:3, 3] += [2.0, 0.0, 0.0]
    m.integrate(dataclasses.replace(frames[1], T_wc=far))
    assert m.finish().meta["pose_jumps"] == [{"frame": 1, "metres": pytest.approx(2.0, abs=0.2)}]


class _Flaky(Detector):
    """Fails on every fourth frame and on frames 5 and 9, in two different ways."""

    id = "flaky"

    def __init__(self, inner: Detector) -> None:
        self.inner = inner

    def detect(self, frame):  # type: ignore[no-untyped-def]
        if frame.index % 4 == 3:
            raise RuntimeError(f"model crashed on input {frame.index}")
        if frame.index in (5, 9):
            raise FrameError(frame.index, "bad image")
        return self.inner.detect(frame)


def test_detector_failures_keep_the_geometry(embedder) -> None:  # type: ignore[no-untyped-def]
    frames = orbit(24)
    blind = _mapper(embedder, detector=_Fixed([]))
    flaky = _mapper(embedder, detector=_Flaky(create_detector("sim", noise="oracle")))
    for f in frames:
        assert blind.integrate(f) and flaky.integrate(f)
    a, b = blind.finish(), flaky.finish()
    assert b.meta["frames_used"] == len(frames) and not b.meta["frames_skipped"]
    assert len(b.voxels) == len(a.voxels)  # every frame's depth is fused, detections or not
    assert np.array_equal(b.voxels.keys, a.voxels.keys)
    assert np.array_equal(b.occupancy.cells, a.occupancy.cells)
    errs = {e["kind"]: (e["count"], e["first_frame"]) for e in b.meta["detector_errors"]}
    assert errs == {"RuntimeError: model crashed on input #": (6, 3), "FrameError: bad image": (2, 5)}
    assert b.objects and not a.objects  # the frames it did detect on still give objects
    with pytest.raises(RuntimeError, match="model crashed"):
        _mapper(embedder, strict=True, detector=_Flaky(_Fixed([]))).integrate(frames[3])
