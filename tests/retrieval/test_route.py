"""Routes into a room resolved against the map's own room regions: the order things are met from
the way in, and left / right as seen walking through it. A scene written for these tests: a
living room (x < 3.8) and a bedroom (x > 3.8) joined by one doorway at y 2.5-3.5; walking east
into the bedroom, north is on the left."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse as parse_mod
from language.synth import make_obj, offline_retriever, room_of, two_rooms

needs_spacy = pytest.mark.skipif(parse_mod.load_parser() is None, reason="spaCy's English pipeline is not installed")


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (120, 120, 120)),
        make_obj(2, "tv", (1.0, 6.3), (1.2, 0.3, 0.7), (30, 30, 30)),
        make_obj(3, "armchair", (2.6, 5.0), (0.8, 0.8, 0.9), (150, 40, 40)),
        make_obj(4, "bed", (7.2, 3.0), (1.6, 2.0, 0.5), (40, 70, 170)),
        make_obj(5, "nightstand", (8.3, 1.5), (0.5, 0.4, 0.6), (120, 90, 60)),
        make_obj(6, "chair", (4.8, 5.6), (0.5, 0.5, 0.9), (200, 200, 200)),  # north of the way in, near it
        make_obj(7, "chair", (5.6, 0.6), (0.5, 0.5, 0.9), (200, 200, 200)),  # south, farther
        make_obj(8, "wardrobe", (8.0, 6.2), (1.2, 0.6, 2.0), (230, 230, 230)),
    ]
    r = offline_retriever(objs, two_rooms())
    rooms = room_of(r)
    assert rooms[4] == "bedroom" and rooms[1] == "living room", rooms  # the scene types its rooms
    return r


@needs_spacy
@pytest.mark.parametrize(("text", "oid"), [
    ("walking from the living room into the bedroom, the chair on your left", 6),
    ("as you come into the bedroom from the lounge, which chair is on the right-hand side? go there", 7),
    ("the first chair you get to when you walk into the bedroom from the sitting room", 6),
    ("counting from the doorway to the living room, the second chair", 7),
])
def test_route_order_and_side_come_from_the_map(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason
    assert "way in from the living room" in res.reason


def test_an_origin_room_the_map_does_not_have_is_said_and_ignored(retriever: Retriever) -> None:
    from capnav.retrieval.query import parse_instruction

    q = parse_instruction("the chair", use_parser=False)
    q.origin_room = "kitchen"
    res = retriever.query(q)
    assert res.found and "no region of the map is typed kitchen" in res.reason
