"""Along one side of a route into a room: "the third thing on your left" counts what is passed
walking in, in the order it is passed, and a thing on the far wall that the line walked crosses
is straight ahead, on neither side. And "machine", the head of the washing machine's own name,
is a word for it. A scene written for these tests: a living room (x < 3.8) and a kitchen
(x > 3.8) joined by one doorway at y 2.5-3.5; walking east into the kitchen, north is on the left."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse as parse_mod
from capnav.retrieval.query import parse_instruction
from language.synth import make_obj, offline_retriever, room_of, two_rooms

needs_spacy = pytest.mark.skipif(parse_mod.load_parser() is None, reason="spaCy's English pipeline is not installed")


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (120, 120, 120)),
        make_obj(2, "tv", (1.0, 6.3), (1.2, 0.3, 0.7), (30, 30, 30)),
        make_obj(3, "armchair", (2.6, 5.0), (0.8, 0.8, 0.9), (150, 40, 40)),
        # The kitchen's north wall, on the left walking in: passed in this order.
        make_obj(4, "washing machine", (4.6, 6.3), (0.6, 0.6, 0.9), (235, 235, 235)),
        make_obj(5, "counter", (6.0, 6.3), (1.4, 0.6, 0.9), (150, 120, 90)),
        make_obj(6, "refrigerator", (7.8, 6.3), (0.7, 0.7, 1.8), (200, 200, 205)),
        # The far (east) wall, across the line walked from the door: straight ahead, nearer the
        # door than the refrigerator, its centre a little north of that line.
        make_obj(7, "cabinet", (8.6, 3.2), (0.6, 1.2, 0.9), (120, 80, 50)),
        # The south wall, on the right.
        make_obj(8, "stove", (5.0, 0.5), (0.7, 0.6, 0.9), (40, 40, 40)),
        make_obj(9, "washing machine", (6.6, 0.5), (0.6, 0.6, 0.9), (235, 235, 235)),
    ]
    r = offline_retriever(objs, two_rooms())
    rooms = room_of(r)
    assert rooms[6] == "kitchen" and rooms[1] == "living room", rooms  # the scene types its rooms
    return r


@needs_spacy
@pytest.mark.parametrize(("text", "oid"), [
    ("keep to the wall on your left as you walk into the kitchen from the living room: the third thing you pass", 6),
    ("coming into the kitchen from the lounge, the third thing along the left-hand side", 6),
    ("walking into the kitchen from the sitting room, the second thing on your right", 9),
    ("come through from the living room into the kitchen: which machine is there on your right?", 9),
    ("as you step into the kitchen from the lounge, the machine on your left", 4),
    # The end of the order: "last" / "final".
    ("the last thing on your left as you walk into the kitchen from the living room", 6),
    ("walking into the kitchen from the lounge, the thing on your right that you pass last", 9),
    ("entering the kitchen from the sitting room, the final thing along your left", 6),
])
def test_things_along_a_side_in_the_order_passed(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_machine_is_a_word_for_the_washing_machine() -> None:
    q = parse_instruction("the machine by the window", use_parser=False)
    assert q.category is None and "washing machine" in q.category_alternatives, q.to_dict()
    assert "sofa" not in q.category_alternatives
