""""at" a piece of furniture is beside it: "the chair at the grey desk" is the chair pulled up to
that desk, and the desk's colour is never the chair's; "work at the desk" (no object before it)
still goes to the desk, and "at the end of" keeps its own geometry. A scene written for these
tests, one open room: a grey desk with a white chair at it, a white desk with a grey chair."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import make_obj, offline_retriever


@pytest.fixture(scope="module")
def office() -> Retriever:
    return offline_retriever([
        make_obj(1, "desk", (1.5, 1.0), (1.4, 0.7, 0.75), (128, 128, 128)),
        make_obj(2, "chair", (1.5, 1.75), (0.5, 0.5, 0.9), (235, 235, 230)),
        make_obj(3, "desk", (6.0, 5.0), (1.4, 0.7, 0.75), (235, 235, 230)),
        make_obj(4, "chair", (6.0, 5.75), (0.5, 0.5, 0.9), (128, 128, 128)),
        make_obj(5, "counter", (8.5, 1.0), (1.8, 0.6, 0.9), (150, 120, 90)),
        make_obj(6, "stool", (8.5, 1.6), (0.4, 0.4, 0.7), (235, 235, 230)),
    ])


@pytest.mark.parametrize(("text", "oid"), [
    ("the chair at the grey desk", 2),
    ("the chair at the white desk", 4),
    ("bring me to the seat at the grey desk", 2),
])
def test_at_a_landmark_is_beside_it(office: Retriever, text: str, oid: int) -> None:
    res = office.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_at_reads_as_a_relation_only_after_an_object() -> None:
    q = parse_instruction("the stool at the counter", use_parser=False)
    assert (q.category, q.relation, q.anchor_category) == ("stool", "next to", "counter"), q.to_dict()
    q = parse_instruction("I want to work at the desk", use_parser=False)
    assert q.category == "desk" and q.relation is None, q.to_dict()
    q = parse_instruction("the stool at the end of the counter", use_parser=False)
    assert q.relation == "at the end of", q.to_dict()
