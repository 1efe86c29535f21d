"""A negated relation ("the stool that isn't by the counter", "the lamp not beside the bed")
excludes the candidate the relation names and keeps the target: the landmark of the negated
phrase is never the answer. Scene and sentences written for these tests, none from the
development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "counter", (6.5, 0.5), (2.0, 0.6, 0.9), (200, 200, 200)),
        make_obj(2, "stool", (6.5, 1.2), (0.4, 0.4, 0.6), (90, 90, 90)),  # by the counter
        make_obj(3, "stool", (7.5, 5.5), (0.4, 0.4, 0.6), (90, 90, 90)),
        make_obj(4, "bed", (1.5, 5.0), (1.6, 2.0, 0.5), (40, 70, 170)),
        make_obj(5, "lamp", (2.7, 5.8), (0.3, 0.3, 1.4), (230, 230, 220)),  # beside the bed
        make_obj(6, "lamp", (0.5, 0.5), (0.3, 0.3, 1.4), (230, 230, 220)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


@pytest.mark.parametrize(("text", "category"), [
    ("the stool that isn't by the counter", "stool"),
    ("the lamp that's not beside the bed", "lamp"),
    ("take me to the stool not next to the counter", "stool"),
])
def test_the_negated_landmark_is_not_the_target(text: str, category: str) -> None:
    q = parse_instruction(text)
    assert q.category == category and q.negations, q


@pytest.mark.parametrize(("text", "oid"), [
    ("the stool that isn't by the counter", 3),
    ("the lamp that's not beside the bed", 6),
    ("not the lamp by the bed, the other one", 6),
    ("the stool by the counter", 2),  # the same relation, not negated
])
def test_a_negated_relation_excludes_the_one_it_names(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason
