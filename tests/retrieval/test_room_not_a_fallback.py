"""A room the map shows is not a fallback: when the named room holds candidates and the
verifier refuses them, one standing in another room (with no cue of the named room where it
stands) does not answer instead ("the red stool in the kitchen" is not the hallway's red stool
once the kitchen's stool is blue). A scene written for these tests: a kitchen (x < 4), a
hallway (4 < x < 6) and a bedroom (x > 6)."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from language.synth import grid_with_walls, make_obj, offline_retriever


@pytest.fixture(scope="module")
def three_rooms() -> Retriever:
    return offline_retriever([
        make_obj(1, "stove", (0.6, 6.2), (0.7, 0.6, 0.9), (40, 40, 40)),
        make_obj(2, "refrigerator", (2.0, 6.3), (0.7, 0.7, 1.8), (235, 235, 235)),
        make_obj(3, "counter", (0.5, 3.5), (0.6, 2.0, 0.9), (150, 120, 90)),
        make_obj(4, "stool", (2.5, 1.0), (0.4, 0.4, 0.7), (40, 70, 170)),  # blue, in the kitchen
        make_obj(5, "stool", (5.0, 5.5), (0.4, 0.4, 0.7), (200, 30, 30)),  # red, in the hallway
        make_obj(6, "lamp", (5.2, 0.6), (0.4, 0.4, 1.5), (235, 235, 230)),  # white, in the hallway
        make_obj(7, "bed", (8.0, 3.0), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(8, "nightstand", (9.3, 1.5), (0.45, 0.4, 0.55), (150, 110, 70)),
        make_obj(9, "lamp", (9.3, 5.8), (0.4, 0.4, 1.5), (25, 25, 28)),  # black, in the bedroom
    ], grid_with_walls(-1, -1, 10, 7, [(4.0, (2.5, 3.5)), (6.0, (2.5, 3.5))]))


@pytest.mark.parametrize("text", [
    "the red stool in the kitchen",
    "is there a white lamp in the bedroom?",
    "take me to the white lamp by the bed in the bedroom",
])
def test_a_refused_candidate_of_the_room_is_not_replaced_by_one_elsewhere(three_rooms: Retriever, text: str) -> None:
    res = three_rooms.query(text)
    assert not res.found, res.reason


@pytest.mark.parametrize(("text", "oid"), [
    ("the stool in the kitchen", 4),
    ("the red stool", 5),
    ("the lamp in the bedroom", 9),
    ("the white lamp", 6),
])
def test_the_room_and_the_attribute_apart_still_answer(three_rooms: Retriever, text: str, oid: int) -> None:
    res = three_rooms.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason
