"""The simulator detector's noise model does what its docstring promises."""

from __future__ import annotations

import numpy as np
import pytest
from _synth_scene import HashEmbedder, default_boxes, orbit

from capnav.core.categories import BY_ID, confusable
from capnav.core.errors import FrameError, InputError
from capnav.perception import (
    DETECTORS,
    ENCODERS,
    Detection,
    LabelEmbeddingEncoder,
    SimDetector,
    create_detector,
    create_encoder,
)


@pytest.fixture(scope="module")
def frames() -> list:
    return orbit(40, width=160, height=120)


def test_registry_and_errors() -> None:
    assert "sim" in DETECTORS and "label-embedding" in ENCODERS
    with pytest.raises(InputError, match="unknown detector backend"):
        create_detector("detic-nope")
    with pytest.raises(InputError, match="unknown noise level"):
        create_detector("sim", noise="loud")
    with pytest.raises(InputError, match="bad SimNoise override"):
        create_detector("sim", not_a_field=1.0)


def test_oracle_is_exact(frames: list) -> None:
    det = create_detector("sim", noise="oracle")
    for f in frames[:10]:
        got = {d.label: d for d in det.detect(f)}
        for iid in np.unique(f.gt_instance):
            if iid == 0 or (f.gt_instance == iid).sum() < det.noise.min_area_frac * f.gt_instance.size:
                continue
            cat = BY_ID[int(f.gt_category[f.gt_instance == iid][0])].name
            d = got[cat]
            np.testing.assert_array_equal(d.mask, f.gt_instance == iid)
            assert d.score == 1.0


def test_default_noise_is_seeded_and_degrades(frames: list) -> None:
    a = [create_detector("sim", seed=3).detect(f) for f in frames]
    b = [create_detector("sim", seed=3).detect(f) for f in reversed(frames)][::-1]  # order independent
    for da, db in zip(a, b, strict=True):
        assert [(d.label, d.score, d.box) for d in da] == [(d.label, d.score, d.box) for d in db]
        for x, y in zip(da, db, strict=True):
            np.testing.assert_array_equal(x.mask, y.mask)
    oracle = create_detector("sim", noise="oracle")
    n_or = sum(len(oracle.detect(f)) for f in frames)
    n_def = sum(len(d) for d in a)
    assert 0.5 * n_or < n_def < n_or  # some misses, not most
    c = [create_detector("sim", seed=4).detect(f) for f in frames]
    assert [[d.score for d in x] for x in a] != [[d.score for d in x] for x in c]


def test_confusion_stays_in_group_and_is_near_the_rate(frames: list) -> None:
    det = SimDetector("default", seed=0, confusion_rate=0.3, fp_rate=0.0)
    total = swapped = 0
    for f in frames:
        for d in det.detect(f):
            truth = BY_ID[int(np.bincount(f.gt_category[d.mask]).argmax())].name
            total += 1
            if d.label != truth:
                swapped += 1
                assert d.label in confusable(truth)
    assert total >= 20 and swapped >= 2
    # rate * (2 - q) with q in (0, 1]; only sofa/table/chair/bookshelf have lookalikes, lamp does not
    assert swapped / total < 0.6


def test_misses_grow_with_distance_and_occlusion() -> None:
    from capnav.perception.sim_detector import occluded_outline

    inst = np.zeros((6, 6), np.int32)
    inst[1:5, 1:3] = 1
    inst[1:5, 3:5] = 2
    depth = np.full((6, 6), 3.0, np.float32)
    depth[:, 3:5] = 1.0  # instance 2 is in front of instance 1
    outline, occ = occluded_outline(inst, depth, 0.05)
    assert occ[2, 2] and not occ[2, 3]  # 1's edge next to 2 is occluded, not the other way round
    assert outline[2, 3]
    far = SimDetector("default", seed=0, fp_rate=0.0, dist_free=0.0, dist_scale=0.3)
    near = SimDetector("default", seed=0, fp_rate=0.0)
    frames = orbit(20, width=160, height=120)
    assert sum(len(far.detect(f)) for f in frames) < 0.5 * sum(len(near.detect(f)) for f in frames)


def test_detector_needs_truth_images(frames: list) -> None:
    f = frames[0]
    f2 = type(f)(index=7, rgb=f.rgb, depth=f.depth, K=f.K, T_wc=f.T_wc)
    with pytest.raises(FrameError, match="frame 7"):
        create_detector("sim").detect(f2)


def test_label_encoder_features(frames: list) -> None:
    emb = HashEmbedder()
    enc = create_encoder("label-embedding", embedder=emb, stride=4)
    assert isinstance(enc, LabelEmbeddingEncoder) and enc.dim == 32 and enc.text_space == emb.model_id
    f = frames[0]
    det = create_detector("sim", noise="oracle").detect(f)
    phi = enc.encode(f, det)
    assert phi.shape == (30, 40, 32) and phi.dtype == np.float32
    table = {t: emb.embed([t])[0] for t in ["floor", "wall", *[d.label for d in det]]}
    d0 = max(det, key=lambda d: d.area)
    vs, us = np.nonzero(d0.mask[2::4, 2::4])
    np.testing.assert_allclose(phi[vs[0], us[0]], table[d0.label], atol=1e-6)
    # the bottom rows of a camera pitched down at 1.2 m see the floor unless an object is there
    covered = np.zeros((30, 40), bool)
    for d in det:
        covered |= d.mask[2::4, 2::4]
    r, c = np.nonzero(~covered)
    k = int(np.argmax(r))
    np.testing.assert_allclose(phi[r[k], c[k]], table["floor"], atol=1e-6)
    empty = Detection((0, 0, 1, 1), 0, "x", 0.5, np.zeros((120, 160), bool))
    assert enc.encode(f, [empty]).shape == (30, 40, 32)


def test_boxes_match_masks(frames: list) -> None:
    for d in create_detector("sim").detect(frames[5]):
        ys, xs = np.nonzero(d.mask)
        assert d.box == (xs.min(), ys.min(), xs.max() + 1, ys.max() + 1)
    assert len(default_boxes()) == 5
