"""A relation of nearness the walls rule out: "the lamp next to the stove" when every lamp
stands in another room than the stove, farther from it than the captions' "next to", is not
found (the answer was the nearest lamp through the wall, several metres off). One room region
cut from another by a doorway keeps the pairs that stand close across it. A scene written for
these tests: a kitchen (x < 4), a hallway (4 < x < 6) and a bedroom (x > 6), doors at y 2.5-3.5."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from language.synth import grid_with_walls, make_obj, offline_retriever


@pytest.fixture(scope="module")
def three_rooms() -> Retriever:
    return offline_retriever([
        make_obj(1, "stove", (0.6, 6.2), (0.7, 0.6, 0.9), (40, 40, 40)),
        make_obj(2, "refrigerator", (2.0, 6.3), (0.7, 0.7, 1.8), (235, 235, 235)),
        make_obj(3, "counter", (3.5, 3.0), (0.6, 1.6, 0.9), (150, 120, 90)),  # by the hallway door
        make_obj(4, "stool", (4.4, 3.0), (0.4, 0.4, 0.7), (90, 60, 40)),  # just past that door
        make_obj(5, "bed", (8.0, 3.0), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(6, "nightstand", (9.3, 1.5), (0.45, 0.4, 0.55), (150, 110, 70)),
        make_obj(7, "lamp", (8.8, 5.8), (0.4, 0.4, 1.5), (25, 25, 28)),  # 1.0 m from the wardrobe
        make_obj(8, "wardrobe", (7.0, 6.3), (1.2, 0.6, 2.0), (230, 230, 230)),
    ], grid_with_walls(-1, -1, 10, 7, [(4.0, (2.5, 3.5)), (6.0, (2.5, 3.5))]))


@pytest.mark.parametrize("text", [
    "the lamp next to the stove",
    "is there a nightstand beside the fridge?",
    "take me to the wardrobe by the cooker",
])
def test_a_landmark_behind_walls_refuses(three_rooms: Retriever, text: str) -> None:
    res = three_rooms.query(text)
    assert not res.found, res.reason
    assert "walls" in res.reason


@pytest.mark.parametrize(("text", "oid"), [
    ("the nightstand beside the bed", 6),
    ("the lamp near the wardrobe", 7),
    ("the stool by the counter", 4),  # close across the doorway: another region, not apart
])
def test_near_pairs_still_answer(three_rooms: Retriever, text: str, oid: int) -> None:
    res = three_rooms.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason
