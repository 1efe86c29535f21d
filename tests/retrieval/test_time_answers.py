"""Requests on a map of two recordings, where a retired object and a present one compete.

The present home answers a request that names only a kind (however near the robot a retired one
of that kind stood), a retired object answers "not found, last seen ..." when the request singles
it out (its colour, its superlative) or when nothing of its kind is left. Scene and sentences
written for this test."""

from __future__ import annotations

import pytest

from capnav.language import create_embedder
from capnav.retrieval import Retriever
from language.synth import captioned_map, make_obj

NEAR_GONE_DESK = (2.0, 1.6)  # the robot stands by the place the walnut desk left


def _retire(o, frame: int):  # type: ignore[no-untyped-def]
    o.history = [{"recording": 1, "event": "born", "position": o.position.tolist(), "frame": 1},
                 {"recording": 2, "event": "retired", "position": o.position.tolist(), "frames_empty": 6}]
    o.last_seen = {"recording": 1, "frame": frame, "timestamp": None}
    return o


@pytest.fixture(scope="module")
def scene():  # type: ignore[no-untyped-def]
    emb = create_embedder("minilm")
    objs = [
        make_obj(1, "desk", (7.0, 5.0), (1.3, 0.7, 0.75), (150, 110, 70)),  # stays
        make_obj(2, "desk", (2.0, 1.0), (1.2, 0.6, 0.75), (90, 60, 35)),  # gone
        make_obj(3, "chair", (7.0, 3.6), (0.5, 0.5, 0.9), (40, 60, 190)),  # blue, stays
        make_obj(4, "chair", (1.0, 5.0), (0.4, 0.4, 0.8), (235, 120, 170)),  # pink, small, gone
        make_obj(5, "sofa", (4.0, 6.0), (2.0, 0.9, 0.8), (120, 120, 120)),  # gone, the only sofa
        make_obj(6, "lamp", (4.0, 3.0), (0.4, 0.4, 1.6), (230, 200, 60)),
    ]
    cmap = captioned_map(objs, emb)
    gone = {2: 40, 4: 55, 5: 70}
    cmap.retired = [_retire(o, gone[o.id]) for o in cmap.objects if o.id in gone]
    cmap.objects = [o for o in cmap.objects if o.id not in gone]
    cmap.meta["recordings"] = [{"index": 1, "label": "visit 1"}, {"index": 2, "label": "visit 2"}]
    return Retriever(cmap, emb)


@pytest.mark.parametrize("text", ["the desk", "take me to the writing desk", "go to the desk please"])
def test_a_kind_is_answered_by_what_is_there_now(scene, text: str) -> None:  # type: ignore[no-untyped-def]
    res = scene.query(text, robot_xy=NEAR_GONE_DESK)
    assert res.found and res.chosen is not None and res.chosen.id == 1, res.reason


def test_the_nearest_one_is_among_the_present(scene) -> None:  # type: ignore[no-untyped-def]
    res = scene.query("the closest chair to me", robot_xy=(1.2, 4.6))  # by the pink chair's old place
    assert res.found and res.chosen is not None and res.chosen.id == 3, res.reason


@pytest.mark.parametrize("text", ["the pink chair", "the smallest chair", "find the couch"])
def test_a_request_that_singles_out_a_retired_object_is_not_found(scene, text: str) -> None:  # type: ignore[no-untyped-def]
    res = scene.query(text, robot_xy=(7.0, 3.0))  # the robot stands by the blue chair
    assert not res.found and res.chosen is None, res.reason
    assert "no longer there" in res.reason and "last seen in visit 1" in res.reason


def test_a_present_object_that_fits_the_words_still_wins(scene) -> None:  # type: ignore[no-untyped-def]
    res = scene.query("the blue chair", robot_xy=(1.2, 4.6))
    assert res.found and res.chosen is not None and res.chosen.id == 3, res.reason
