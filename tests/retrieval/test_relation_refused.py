"""A nearness relation that no candidate meets is refused ("not found", saying which relation and
how far the nearest one stands), the best candidate kept aside for a search; one met by one of two
lookalikes picks that one; a loose word ("near") takes a near-miss that a tight one ("beside")
refuses. Sentences written for this test."""

from __future__ import annotations

from capnav.retrieval import Retriever
from language.synth import make_obj, offline_retriever, two_rooms


def _lounge(chair_x: float) -> Retriever:
    # one room left of the wall at x = 3.8; the sofa's right side at x = 2.0
    objs = [
        make_obj(1, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (90, 60, 40)),
        make_obj(2, "armchair", (chair_x, 1.0), (0.8, 0.8, 0.9), (60, 90, 150)),
        make_obj(3, "tv", (1.0, 5.5), (1.2, 0.3, 0.7), (20, 20, 20)),
        make_obj(4, "bookshelf", (0.2, 3.5), (0.4, 1.0, 1.8), (150, 110, 70)),
    ]
    return offline_retriever(objs, two_rooms())


def test_nobody_beside_the_landmark_is_refused_with_the_gap() -> None:
    r = _lounge(3.35)  # 2.95 - 2.0 = 0.95 m: beside
    res = r.query("take me to the armchair beside the couch")
    assert res.found and res.chosen is not None and res.chosen.id == 2
    objs = [
        make_obj(1, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (90, 60, 40)),
        make_obj(2, "armchair", (1.0, 3.35), (0.8, 0.8, 0.9), (60, 90, 150)),  # 1.5 m from the sofa
        make_obj(3, "tv", (1.0, 6.3), (1.2, 0.3, 0.7), (20, 20, 20)),
    ]
    r = offline_retriever(objs, two_rooms())
    res = r.query("I'd like the easy chair that sits beside the couch")
    assert not res.found and res.chosen is None, res.reason
    assert "no armchair stands next to a sofa" in res.reason and "1.5 m" in res.reason, res.reason
    # what a search needs: the best candidate and the relation it fails
    assert res.unmet_candidate is not None and res.unmet_candidate.id == 2
    assert res.unmet is not None and "1.5 m" in res.unmet
    d = res.to_dict()
    assert d["found"] is False and d["chosen"] is None
    assert d["unmet_candidate"]["id"] == 2 and d["unmet"] == res.unmet


def test_the_lookalike_that_meets_the_relation_is_chosen() -> None:
    objs = [
        make_obj(1, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (90, 60, 40)),
        make_obj(2, "armchair", (1.0, 4.2), (0.8, 0.8, 0.9), (60, 90, 150)),  # 2.35 m from the sofa
        make_obj(3, "armchair", (2.6, 1.0), (0.8, 0.8, 0.9), (60, 90, 150)),  # 0.2 m from it
        make_obj(4, "tv", (1.0, 6.3), (1.2, 0.3, 0.7), (20, 20, 20)),
    ]
    r = offline_retriever(objs, two_rooms())
    res = r.query("find the lounge chair next to the settee please")
    assert res.found and res.chosen is not None and res.chosen.id == 3, res.reason
    assert res.unmet is None and res.unmet_candidate is None


def test_a_loose_word_takes_a_near_miss_a_tight_one_refuses() -> None:
    objs = [
        make_obj(1, "bed", (1.5, 1.2), (1.6, 2.0, 0.5), (230, 230, 235)),
        make_obj(2, "lamp", (1.5, 3.65), (0.3, 0.3, 1.5), (200, 40, 40)),  # 1.3 m from the bed
        make_obj(3, "wardrobe", (0.2, 5.8), (0.6, 1.2, 2.0), (120, 80, 50)),
    ]
    r = offline_retriever(objs, two_rooms())
    loose = r.query("go to the lamp near the bed")
    assert loose.found and loose.chosen is not None and loose.chosen.id == 2, loose.reason
    assert loose.unmet is not None  # still said: farther than "next to"
    tight = r.query("go to the lamp right beside the bed")
    assert not tight.found and tight.unmet_candidate is not None and tight.unmet_candidate.id == 2, tight.reason
    objs[1] = make_obj(2, "lamp", (1.5, 3.85), (0.3, 0.3, 1.5), (200, 40, 40))  # 1.5 m: near it no more
    far = offline_retriever(objs, two_rooms()).query("go to the lamp near the bed")
    assert not far.found and "the nearest is 1.5 m away" in far.reason, far.reason
