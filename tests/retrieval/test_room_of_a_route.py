"""A room named by the verb or the preposition of a route is where the target stands: "as you enter
the kitchen", "when you come into the lounge", "along the corridor", "down the hall". The room
is the object of a verb of entering or of a preposition one walks along, not of "in"; it must
not become unknown words. Scene and sentences written for these tests, none from the
development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import bedroom_and_lounge


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    return bedroom_and_lounge()


@pytest.mark.parametrize(("text", "room"), [
    ("the first chair as you enter the kitchen", "kitchen"),
    ("the first chair on the right as you enter the living room", "living room"),
    ("the bed you see when you enter the guest room", "bedroom"),
    ("the lamp along the corridor", "hallway"),
    ("the third plant along the hallway", "hallway"),
    ("the lamp down the hall", "hallway"),
])
def test_a_route_room_is_where_the_target_stands(text: str, room: str) -> None:
    q = parse_instruction(text)
    assert q.room == room, vars(q)
    assert not set(q.unknown_words) & {"enter", "kitchen", "living", "corridor", "hallway", "hall", "along",
                                       "down", "guest"}, vars(q)


def test_a_room_walked_through_is_not_where_the_target_stands() -> None:
    q = parse_instruction("the lamp you pass when you walk through the kitchen into the lounge")
    assert q.room == "living room", vars(q)


@pytest.mark.parametrize(("text", "oid"), [
    ("take me to the lamp as you enter the living room", 5),
    ("the lamp you see as you enter the bedroom", 2),
])
def test_the_entered_room_chooses_the_object(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "room"), [
    ("the lamp in the main bedroom", "bedroom"),
    ("the dresser opposite the bed in the main bedroom", "bedroom"),
    ("the sink in the upstairs bathroom", "bathroom"),
    ("the chair in the blue bedroom", "bedroom"),
    ("the lamp in the second bedroom", "bedroom"),
    ("the plant in our big kitchen", "kitchen"),
])
def test_words_before_a_room_name_describe_the_room(text: str, room: str) -> None:
    """An adjective or ordinal on the room ("the main bedroom", "the blue bedroom", "the second
    bedroom") belongs to the room: the room is kept and the word is not the target's."""
    q = parse_instruction(text)
    assert q.room == room, vars(q)
    assert not q.colors and q.ordinal is None and q.size_word is None, vars(q)
    assert not set(q.unknown_words) & {"bedroom", "bathroom", "kitchen"}, vars(q)


def test_an_ordinal_before_a_room_word_that_names_an_object_counts_the_object() -> None:
    q = parse_instruction("the first kitchen chair")
    assert q.ordinal == 1, vars(q)
