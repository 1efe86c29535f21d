"""A category after "with" / "that has" that is no piece of the target is another object beside
it: "the desk with the blue chair at it" is the desk next to the blue chair, and "blue" is the
chair's, not the desk's (it was read as the desk's colour, and every desk was refused). A piece
of the target ("a chair with a velvet seat", "the dresser with the glass top") stays a piece.
Scene and sentences written for these tests (helper fresh22), none from a development set."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import make_obj, offline_retriever

DESK_A, DESK_B, CHAIR_BLUE, CHAIR_RED, TABLE, STOOL = 1, 2, 3, 4, 5, 6


@pytest.fixture(scope="module")
def study() -> Retriever:
    return offline_retriever([
        make_obj(DESK_A, "desk", (1.0, 1.0), (1.2, 0.6, 0.75), (200, 200, 200)),
        make_obj(DESK_B, "desk", (6.0, 1.0), (1.2, 0.6, 0.75), (200, 200, 200)),
        make_obj(CHAIR_BLUE, "chair", (1.0, 1.7), (0.5, 0.5, 0.9), (30, 60, 200)),
        make_obj(CHAIR_RED, "chair", (6.0, 1.7), (0.5, 0.5, 0.9), (200, 30, 30)),
        make_obj(TABLE, "table", (3.5, 5.0), (1.4, 0.8, 0.75), (120, 90, 60)),
        make_obj(STOOL, "stool", (3.5, 5.8), (0.4, 0.4, 0.6), (40, 160, 40)),
    ])


@pytest.mark.parametrize(("text", "oid"), [
    ("the desk with the blue chair at it", DESK_A),
    ("the desk that has the red chair in front of it", DESK_B),
    ("take me to the desk with a red chair", DESK_B),
])
def test_the_object_it_has_by_it_is_a_landmark(study: Retriever, text: str, oid: int) -> None:
    res = study.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "anchor", "colours"), [
    ("the table with the green stool", "stool", []),
    ("the desk which has the blue chair next to it", "chair", []),
])
def test_the_words_of_the_landmark_are_not_the_targets(text: str, anchor: str, colours: list[str]) -> None:
    q = parse_instruction(text)
    assert q.anchor_category == anchor and q.relation == "next to" and q.colors == colours, q


@pytest.mark.parametrize(("text", "part"), [
    ("an armchair with a leather seat", "seat"),
    ("the dresser with the marble top", "top"),
])
def test_a_piece_of_the_target_stays_a_piece(text: str, part: str) -> None:
    q = parse_instruction(text)
    assert q.anchor_category is None and part in q.part_materials, q


@pytest.mark.parametrize("text", [
    "the bookcase with the tall shelves",  # its own shelves (a form of its own category)
    "the cupboard with the stone top",  # "stone" is no stove, though one letter from it
])
def test_no_landmark_from_its_own_category_or_a_misspelling(text: str) -> None:
    q = parse_instruction(text)
    assert q.anchor_category is None and q.relation is None, q
