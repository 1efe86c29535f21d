"""Eq. 12 against a hand-computed cost and every branch of Algorithm 1."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.mapping import LiftedDetection, SG3DTracker, TrackerConfig
from capnav.mapping.cost import association_cost, box_iou
from capnav.perception import Detection


def lifted(pos: tuple[float, float, float], box: tuple[float, float, float, float] = (0, 0, 10, 10),
           cls: int = 3, feat: tuple[float, ...] = (1.0, 0.0), label: str = "chair", score: float = 0.9
           ) -> LiftedDetection:
    det = Detection(box=box, class_id=cls, label=label, score=score, mask=np.zeros((4, 4), bool))
    return LiftedDetection(index=0, detection=det, position=np.array(pos, float),
                           descriptor=np.array(feat, np.float32), points=np.zeros((0, 3), np.float32),
                           colors=np.zeros((0, 3), np.uint8), distance=1.0, visibility=1.0, truncated=False)


def test_eq12_cost_by_hand() -> None:
    # track at (0,0,0), box (0,0,10,10), feature (1,0), class 3
    # detection at (0.3,0.4,0) -> d = 0.5; box (5,0,15,10) -> IoU = 50/150; feature (1,1)/sqrt2 -> cos = 0.7071; class 4
    d_max, w = 1.0, (0.6, 0.2, 0.2, 0.3)
    expect = 0.6 * 0.5 / 1.0 + 0.2 * (1 - 1 / 3) + 0.2 * (1 - np.sqrt(0.5)) + 0.3 * 1
    gated, raw = association_cost(np.zeros((1, 3)), np.array([[0, 0, 10, 10]]), np.array([[1.0, 0.0]]),
                                  np.array([3]), np.array([[0.3, 0.4, 0.0]]), np.array([[5, 0, 15, 10]]),
                                  np.array([[1.0, 1.0]]), np.array([4]), w, d_max, tau_assoc=10.0)
    assert raw[0, 0] == pytest.approx(expect)
    assert gated[0, 0] == pytest.approx(expect)
    g2, _ = association_cost(np.zeros((1, 3)), np.array([[0, 0, 10, 10]]), np.array([[1.0, 0.0]]), np.array([3]),
                             np.array([[0.3, 0.4, 0.0]]), np.array([[5, 0, 15, 10]]), np.array([[1.0, 1.0]]),
                             np.array([4]), w, d_max, tau_assoc=expect - 1e-6)
    assert np.isinf(g2[0, 0])  # tau gate
    g3, _ = association_cost(np.zeros((1, 3)), np.array([[0, 0, 10, 10]]), np.array([[1.0, 0.0]]), np.array([3]),
                             np.array([[0.3, 0.4, 0.0]]), np.array([[0, 0, 10, 10]]), np.array([[1.0, 0.0]]),
                             np.array([3]), w, d_max=0.45, tau_assoc=10.0)
    assert np.isinf(g3[0, 0])  # distance gate
    assert box_iou(np.array([[0, 0, 10, 10]]), np.array([[20, 20, 30, 30]]))[0, 0] == 0.0


def test_birth_match_ema_and_export() -> None:
    cfg = TrackerConfig(h_min=2, alpha_pos=0.5, alpha_bbox=0.5)
    tr = SG3DTracker(cfg)
    s1 = tr.update([lifted((0, 0, 0))])
    assert len(s1.births) == 1 and not s1.matches and not s1.confirmed  # hits 1 < h_min
    t = s1.births[0][0]
    assert (t.age, t.hits, t.misses) == (1, 1, 0)
    np.testing.assert_allclose(t.velocity, 0.0)
    s2 = tr.update([lifted((0.04, 0.0, 0.0), box=(2, 0, 12, 10))])
    assert s2.matches == [(t, 0)] and not s2.births
    np.testing.assert_allclose(t.position, [0.02, 0, 0])  # alpha_pos EMA
    np.testing.assert_allclose(t.velocity, [0.02, 0, 0])  # v = p - p_prev
    np.testing.assert_allclose(t.box, [1, 0, 11, 10])  # alpha_bbox EMA
    assert (t.hits, t.misses) == (2, 0)
    assert s2.confirmed == [t]  # hits >= h_min and misses == 0
    np.testing.assert_allclose(tr.predict()[0], [0.04, 0, 0])  # eq. 11 constant velocity


def test_gated_pair_gives_birth_and_assignment_is_optimal() -> None:
    tr = SG3DTracker(TrackerConfig())
    tr.update([lifted((0, 0, 0)), lifted((0.6, 0, 0))])
    # Greedy would give det (0.35) to track 0 (closest pair overall); the optimum swaps nothing here
    # but the far detection (5 m away) must be born, not matched.
    s = tr.update([lifted((0.05, 0, 0)), lifted((0.62, 0, 0)), lifted((5, 0, 0))])
    assert sorted(i for _, i in s.matches) == [0, 1]
    assert [i for _, i in s.births] == [2]
    ids = {t.id: i for t, i in s.matches}
    assert ids == {1: 0, 2: 1}


def test_class_and_semantic_terms_separate_neighbours() -> None:
    tr = SG3DTracker(TrackerConfig())
    tr.update([lifted((0, 0, 0), cls=3, feat=(1, 0), label="chair"),
               lifted((0.3, 0, 0), cls=5, feat=(0, 1), label="table")])
    s = tr.update([lifted((0.28, 0, 0), cls=3, feat=(1, 0), label="chair"),
                   lifted((0.02, 0, 0), cls=5, feat=(0, 1), label="table")])
    got = {t.label: i for t, i in s.matches}
    assert got == {"chair": 0, "table": 1}


def test_death_after_m_max_misses() -> None:
    tr = SG3DTracker(TrackerConfig(m_max=2))
    tr.update([lifted((0, 0, 0))])
    for k in range(2):
        s = tr.update([])
        assert not s.deaths and tr.tracks[0].misses == k + 1
    s = tr.update([])
    assert len(s.deaths) == 1 and not tr.tracks  # misses 3 > m_max
    assert s.deaths[0].age == 4


def test_velocity_is_clipped() -> None:
    tr = SG3DTracker(TrackerConfig(max_speed=0.05, alpha_pos=1.0))
    tr.update([lifted((0, 0, 0))])
    tr.update([lifted((0.5, 0, 0))])
    assert np.linalg.norm(tr.tracks[0].velocity) == pytest.approx(0.05)
