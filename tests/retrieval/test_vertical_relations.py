"""Above, below, under, on top of: a relation to a landmark, not the landmark. "The mirror above
the sink" asks for a mirror (the map has none: not found), never for the sink it hangs over; "the
lamp above the desk" is the lamp whose footprint touches the desk's. Sentences and scene written
for these tests, none from the development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "sink", (1.0, 1.0), (0.6, 0.5, 0.9), (240, 240, 240)),
        make_obj(2, "desk", (2.5, 5.5), (1.2, 0.6, 0.75), (120, 80, 50)),
        make_obj(3, "lamp", (2.9, 5.6), (0.3, 0.3, 0.5), (30, 30, 30)),  # stands on the desk
        make_obj(4, "lamp", (0.5, 3.0), (0.4, 0.4, 1.5), (30, 30, 30)),
        make_obj(5, "counter", (7.0, 1.0), (2.0, 0.6, 0.9), (200, 200, 200)),
        make_obj(6, "stool", (7.2, 1.5), (0.4, 0.4, 0.6), (90, 90, 90)),  # tucked under the counter
        make_obj(7, "stool", (6.5, 5.0), (0.4, 0.4, 0.6), (90, 90, 90)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


@pytest.mark.parametrize(("text", "relation", "anchor"), [
    ("take me to the mirror hanging above the sink", "above", "sink"),
    ("the picture on top of the dresser", "on top of", "dresser"),
    ("go to the rug underneath the coffee table", "underneath", "coffee table"),
])
def test_the_landmark_is_not_the_target(text: str, relation: str, anchor: str) -> None:
    q = parse_instruction(text)
    assert q.category is None and q.relation == relation and q.anchor_category == anchor, q


@pytest.mark.parametrize("text", ["take me to the mirror hanging above the sink", "the mirror above the sink"])
def test_an_absent_thing_over_a_landmark_is_not_found(retriever: Retriever, text: str) -> None:
    res = retriever.query(text)
    assert not res.found, res.reason


@pytest.mark.parametrize(("text", "oid"), [
    ("the lamp on top of the desk", 3),
    ("could you go to the stool under the counter", 6),
    ("the stool beneath the counter", 6),
])
def test_a_thing_above_or_below_a_landmark_is_the_one_touching_it(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "anchor"), [
    ("the lamp on the desk", "desk"),
    ("the vase on the table", "table"),
    ("the plant sitting on the bookshelf", "bookshelf"),
    ("take me to the cup on the kitchen counter", "counter"),
])
def test_on_a_landmark_is_a_relation(text: str, anchor: str) -> None:
    """"on the desk" is where the thing stands: the desk is a landmark, never an unknown word."""
    q = parse_instruction(text)
    assert q.relation == "on top of" and q.anchor_category == anchor, vars(q)
    assert anchor not in q.unknown_words, vars(q)


@pytest.mark.parametrize(("text", "side"), [
    ("the lamp on the left", "left"),
    ("the stool on your right", "right"),
])
def test_on_a_side_is_no_landmark(text: str, side: str) -> None:
    q = parse_instruction(text)
    assert q.relation is None and q.anchor_category is None, vars(q)


def test_the_lamp_on_the_desk_is_the_one_standing_on_it(retriever: Retriever) -> None:
    res = retriever.query("the lamp on the desk")
    assert res.found and res.chosen is not None and res.chosen.id == 3, res.reason


@pytest.mark.parametrize(("text", "goal"), [
    ("I put my phone down on the nightstand, can you go there", "nightstand"),
    ("we placed the keys on the coffee table, take me to it", "coffee table"),
    ("she set her mug on the counter earlier", "counter"),
])
def test_on_after_putting_something_down_is_where_it_was_put(text: str, goal: str) -> None:
    """The place something was put down on is the goal, not a landmark of the thing put."""
    q = parse_instruction(text)
    assert q.category == goal and q.relation is None, vars(q)
