"""Baseline building blocks on hand-built data: goal words, VLMaps' top-down pooling and regions,
and the harness's retrieval judgement."""

from __future__ import annotations

import numpy as np

from capnav.core.footprint import footprint_distance
from capnav.core.grid import GridSpec
from capnav.eval.baselines.vlmaps import VlmapsStyle, goal_regions, region_polygon, topdown_features
from capnav.eval.episode_runner import retrieval_correct
from capnav.eval.generate import SceneTruth
from capnav.eval.methods.words import category_in_text


def test_category_in_text() -> None:
    assert category_in_text("the red chair next to the sofa") == "chair"
    assert category_in_text("Take me to the couch, please") == "sofa"
    assert category_in_text("the smallest coffee table") == "coffee table"  # not "table"
    assert category_in_text("the tallest bookcases") == "bookshelf"
    assert category_in_text("the piano") is None
    # the same reading as CapNav's parser: typos, and the target rather than the landmark
    assert category_in_text("Take me to the smalest lounge chiar.") == "armchair"
    assert category_in_text("the lamp next to the sofa") == "lamp"
    assert category_in_text("   ") is None


def test_topdown_features_pool_and_normalise() -> None:
    spec = GridSpec(0.0, 0.0, 1.0, 2, 2)
    centers = np.array([[0.5, 0.5, 0.5], [0.5, 0.5, 1.0], [1.5, 0.5, 0.5], [1.5, 1.5, 0.01], [1.5, 1.5, 5.0]])
    feats = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 2.0], [1.0, 0.0], [1.0, 0.0]], dtype=np.float32)
    w = np.array([3.0, 1.0, 1.0, 1.0, 1.0])
    cells, f = topdown_features(centers, feats, w, spec, (0.05, 2.0))
    # cell (0, 0): weighted mean of [1, 0] x3 and [0, 1] x1 -> [3, 1] / |.|; cell (0, 1): [0, 1];
    # cell (1, 1) has only a floor voxel and a ceiling voxel: outside the height band
    assert cells.tolist() == [[0, 0], [0, 1]]
    np.testing.assert_allclose(f, [[3 / np.sqrt(10), 1 / np.sqrt(10)], [0.0, 1.0]], rtol=1e-6)


def test_goal_regions_and_polygon() -> None:
    won = np.zeros((6, 6), dtype=bool)
    won[0:2, 0:2] = True  # a 4-cell region
    won[5, 5] = True  # speckle
    labels, ids = goal_regions(won, min_cells=3)
    assert len(ids) == 1 and labels[0, 0] == ids[0] and labels[5, 5] not in ids
    only_speckle = np.zeros((6, 6), dtype=bool)
    only_speckle[3, 3] = True
    assert len(goal_regions(only_speckle, min_cells=3)[1]) == 1  # speckle kept if it is all there is
    spec = GridSpec(0.0, 0.0, 0.5, 6, 6)
    poly = region_polygon(np.argwhere(won & (labels == ids[0])), spec)
    # the region covers x, y in [0, 1]: inside points have distance 0, a point 1 m to the right 1 m
    d = footprint_distance(np.array([[0.5, 0.5], [2.0, 0.5]]), poly)
    np.testing.assert_allclose(d, [0.0, 1.0], atol=1e-9)


def test_vlmaps_label_list_excludes_the_named_category() -> None:
    labels = VlmapsStyle().labels_for("the blue couch")
    assert labels[0] == "the blue couch" and "sofa" not in labels and "armchair" in labels and "floor" in labels


def test_retrieval_correct_needs_the_right_instance() -> None:
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    t = SceneTruth(0, {1: "chair", 2: "chair"}, {1: sq, 2: sq + np.array([1.3, 0.0])}, GridSpec(0, 0, 0.1, 10, 30),
                   np.ones((10, 30), dtype=bool))
    assert retrieval_correct(t, (0.5, 0.5), [1]) is True
    assert retrieval_correct(t, (1.1, 0.5), [1]) is True  # 0.1 m from chair 1, 0.2 m from chair 2
    assert retrieval_correct(t, (1.2, 0.5), [1]) is False  # 0.2 m from 1 but 0.1 m from 2: the lookalike
    assert retrieval_correct(t, (2.0, 0.5), [1]) is False
    assert retrieval_correct(t, (2.0, 0.5), [1, 2]) is True  # label protocol: any instance
    assert retrieval_correct(t, None, [1]) is None
