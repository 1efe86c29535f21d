"""An answer that does not meet the request's nearness relation (the only armchair stands 1.6 m
from the sofa, "next to" is 1.2 m) says so in its reason and in ``capnav query --json``'s
``unmet``: asked "beside", the query refuses and keeps the armchair as ``unmet_candidate`` (a
robot's search looks on from it); asked with the looser "near" 1.3 m off, it is the answer, the miss said."""

from __future__ import annotations

from capnav.retrieval import Retriever
from language.synth import make_obj, offline_retriever, two_rooms


def _scene(chair_y: float = 3.45) -> Retriever:
    objs = [
        make_obj(1, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (120, 120, 120)),
        make_obj(2, "armchair", (1.0, chair_y), (0.8, 0.8, 0.9), (210, 200, 170)),  # 1.6 m from the sofa
        make_obj(3, "tv", (1.0, 6.3), (1.2, 0.3, 0.7), (30, 30, 30)),
        make_obj(4, "lamp", (2.6, 1.0), (0.3, 0.3, 1.5), (230, 230, 220)),  # beside the sofa
    ]
    return offline_retriever(objs, two_rooms())


def test_a_relation_not_met_is_said_in_the_reason_and_the_json() -> None:
    r = _scene()
    res = r.query("the armchair beside the sofa")
    assert not res.found and res.chosen is None
    assert res.unmet_candidate is not None and res.unmet_candidate.id == 2
    assert res.unmet is not None and "1.6 m" in res.unmet, res.unmet
    assert "no armchair stands next to a sofa: the nearest is 1.6 m away" in res.reason, res.reason
    assert res.unmet in res.reason
    assert res.to_dict()["unmet"] == res.unmet and res.to_dict()["unmet_candidate"]["id"] == 2
    near = _scene(3.15)  # 1.3 m: beyond "next to", within a loose "near" (one quarter-metre bin more)
    loose = near.query("the armchair near the sofa")
    assert loose.found and loose.chosen is not None and loose.chosen.id == 2
    assert loose.unmet is not None and "1.3 m" in loose.unmet and "does not meet the request's relation" in loose.reason
    assert loose.to_dict()["unmet"] == loose.unmet and loose.to_dict()["unmet_candidate"] is None
    met = r.query("the lamp beside the sofa")
    assert met.found and met.chosen is not None and met.chosen.id == 4
    assert met.unmet is None and met.to_dict()["unmet"] is None and "does not meet" not in met.reason
