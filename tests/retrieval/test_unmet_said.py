"""An answer that does not meet the request's nearness relation (the only armchair stands 1.6 m
from the sofa, "next to" is 1.2 m) says so in its reason and in ``capnav query --json``'s
``unmet``: the best there is, not what was asked; a user and a robot's search can judge it."""

from __future__ import annotations

from capnav.retrieval import Retriever
from language.synth import make_obj, offline_retriever, two_rooms


def _scene() -> Retriever:
    objs = [
        make_obj(1, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (120, 120, 120)),
        make_obj(2, "armchair", (1.0, 3.45), (0.8, 0.8, 0.9), (210, 200, 170)),  # 1.6 m from the sofa
        make_obj(3, "tv", (1.0, 6.3), (1.2, 0.3, 0.7), (30, 30, 30)),
        make_obj(4, "lamp", (2.6, 1.0), (0.3, 0.3, 1.5), (230, 230, 220)),  # beside the sofa
    ]
    return offline_retriever(objs, two_rooms())


def test_a_relation_not_met_is_said_in_the_reason_and_the_json() -> None:
    r = _scene()
    res = r.query("the armchair beside the sofa")
    assert res.found and res.chosen is not None and res.chosen.id == 2
    assert res.unmet is not None and "1.6 m" in res.unmet, res.unmet
    assert "does not meet the request's relation" in res.reason
    assert res.to_dict()["unmet"] == res.unmet
    met = r.query("the lamp beside the sofa")
    assert met.found and met.chosen is not None and met.chosen.id == 4
    assert met.unmet is None and met.to_dict()["unmet"] is None and "does not meet" not in met.reason
