"""A landmark of the target's own kind, told apart from its lookalikes: by its size ("the
nightstand beside the bigger bed", "the lamp by the shortest lamp"), and by a phrase after the
word standing in for it ("the plant next to the one in the blue pot", "the chair nearest the one
that is red"), whose words describe the landmark, never the target. A scene written for these
tests, one open room: two beds of clearly different sizes, each with a nightstand (the bigger
bed's the smaller one, so that a size word read as the target's picks the wrong one), chairs
and two lamps of different heights, three plants."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import make_obj, offline_retriever


@pytest.fixture(scope="module")
def room() -> Retriever:
    return offline_retriever([
        make_obj(1, "bed", (1.5, 1.5), (2.0, 1.8, 0.6), (200, 200, 200)),  # the bigger bed
        make_obj(2, "nightstand", (3.0, 0.6), (0.35, 0.35, 0.45), (120, 90, 60)),  # the smaller one
        make_obj(3, "bed", (8.0, 1.2), (1.9, 0.9, 0.5), (200, 200, 200)),  # the smaller bed
        make_obj(4, "nightstand", (6.6, 0.5), (0.6, 0.5, 0.65), (120, 90, 60)),  # the bigger one
        make_obj(5, "plant", (1.0, 6.0), (0.4, 0.4, 0.9), (40, 140, 50)),
        make_obj(6, "plant", (1.7, 6.0), (0.4, 0.4, 0.9), (40, 70, 170)),  # the blue one, by plant 5
        make_obj(7, "plant", (8.5, 6.0), (0.4, 0.4, 0.9), (40, 140, 50)),
        make_obj(8, "chair", (4.0, 4.0), (0.5, 0.5, 0.9), (200, 30, 30)),  # red
        make_obj(9, "chair", (4.8, 4.0), (0.5, 0.5, 0.9), (235, 235, 230)),  # white, by the red one
        make_obj(10, "chair", (8.5, 3.8), (0.5, 0.5, 0.9), (235, 235, 230)),  # white, far
        make_obj(11, "lamp", (6.0, 6.5), (0.4, 0.4, 1.0), (30, 30, 30)),  # the short lamp
        make_obj(12, "lamp", (6.8, 6.5), (0.4, 0.4, 1.7), (30, 30, 30)),
        make_obj(13, "lamp", (0.3, 3.5), (0.4, 0.4, 1.7), (30, 30, 30)),
    ])


@pytest.mark.parametrize(("text", "oid"), [
    ("the nightstand beside the bigger bed", 2),
    ("the nightstand next to the smaller of the beds", 4),
    ("the nightstand by the little bed", 4),
    ("the plant next to the one in the blue pot", 5),
    ("the chair nearest the one that is red", 9),
    ("the chair closest to the red one", 9),
    ("the lamp nearest the shortest lamp", 12),
])
def test_a_landmark_of_the_target_s_kind_is_picked_by_its_own_words(room: Retriever, text: str, oid: int) -> None:
    res = room.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_the_words_after_the_stand_in_are_the_landmark_s() -> None:
    q = parse_instruction("the plant next to the one with the blue pot", use_parser=False)
    assert q.anchor_category == "plant" and not q.colors, q.to_dict()
    q = parse_instruction("the chair nearest the one that is red", use_parser=False)
    assert q.anchor_category == "chair" and q.proximity_to_anchor and not q.colors, q.to_dict()
