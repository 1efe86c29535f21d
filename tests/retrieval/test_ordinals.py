"""Ordinals counted from somewhere, resolved against the map: from a door named by the room
behind it, from a landmark object, along a corridor, and ordinals said otherwise than as an
adjective of the object ("the one you reach second", "number three", "skip the nearest and take
the next"). Sentences and scene written for these tests.

The scene: a kitchen (x < 3.8), a corridor (3.8 < x < 5.6, no object that types a room) and an
office (x > 5.6); the kitchen-corridor door is at y 2.5-3.5, the corridor-office door at y 0.5-1.5.
Stools counted from the stove: 11, 12, 13; from the fridge: 13, 12, 11. Corridor plants from the
kitchen door: 21, 22. Office from its door: bookshelf 31, desk 34, bookshelf 33, bookshelf 32."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse as parse_mod
from capnav.retrieval.query import parse_goals, parse_instruction
from language.synth import grid_with_walls, make_obj, offline_retriever, room_of

needs_spacy = pytest.mark.skipif(parse_mod.load_parser() is None, reason="spaCy's English pipeline is not installed")


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "stove", (0.3, 6.2), (0.6, 0.6, 0.9), (190, 192, 196)),
        make_obj(2, "refrigerator", (0.0, 0.2), (0.7, 0.7, 1.8), (240, 240, 240)),
        make_obj(3, "counter", (1.6, 6.4), (1.8, 0.6, 0.9), (120, 90, 60)),
        make_obj(11, "stool", (1.0, 5.2), (0.4, 0.4, 0.7), (150, 40, 40)),
        make_obj(12, "stool", (2.0, 3.6), (0.4, 0.4, 0.7), (150, 40, 40)),
        make_obj(13, "stool", (3.0, 1.0), (0.4, 0.4, 0.7), (150, 40, 40)),
        make_obj(21, "plant", (4.7, 4.2), (0.4, 0.4, 1.0), (40, 140, 60)),
        make_obj(22, "plant", (4.7, 6.4), (0.4, 0.4, 1.0), (40, 140, 60)),
        make_obj(31, "bookshelf", (6.2, 2.6), (0.4, 1.0, 1.8), (110, 80, 50)),
        make_obj(32, "bookshelf", (8.0, 6.5), (1.0, 0.4, 1.8), (110, 80, 50)),
        make_obj(33, "bookshelf", (9.6, 0.2), (0.4, 1.0, 1.8), (110, 80, 50)),
        make_obj(34, "desk", (7.5, 3.8), (1.2, 0.6, 0.75), (200, 200, 200)),
    ]
    occ = grid_with_walls(-1, -1, 10, 7, [(3.8, (2.5, 3.5)), (5.6, (0.5, 1.5))])
    r = offline_retriever(objs, occ)
    rooms = room_of(r)
    assert rooms[1] == "kitchen" and rooms[34] == "office" and rooms[21] is None, rooms
    return r


def _answer(r: Retriever, text: str) -> int | None:
    res = r.query(text)
    return res.chosen.id if res.found and res.chosen is not None else None


# -- counted from a door named by the room behind it ----------------------------------------------
@pytest.mark.parametrize(("text", "oid"), [
    ("the second bookshelf from the door to the corridor", 33),
    ("the third bookshelf counting from the corridor door", 32),
    ("Counting from the doorway to the passage, which bookshelf comes second?", 33),
])
def test_an_ordinal_counts_from_the_door_named_by_the_room_behind_it(retriever, text, oid):
    assert _answer(retriever, text) == oid


def test_a_door_to_a_room_is_where_the_count_starts_not_where_the_target_stands():
    q = parse_instruction("the second bookshelf from the door to the corridor")
    assert q.origin_room == "hallway" and q.room != "hallway" and q.ordinal == 2


# -- counted from a landmark -----------------------------------------------------------------------
@pytest.mark.parametrize(("text", "oid"), [
    ("beginning at the stove, the second stool along", 12),
    ("the third stool from the fridge", 11),
    ("start by the fridge and stop at the first stool you come to", 13),
    ("if you begin at the cooker and work your way along, which stool is third?", 13),
])
def test_an_ordinal_counts_from_a_landmark(retriever, text, oid):
    assert _answer(retriever, text) == oid


def test_the_landmark_a_count_starts_from_is_not_the_goal():
    q = parse_instruction("beginning at the stove, the second stool along")
    assert q.category == "stool" and q.anchor_category == "stove" and q.ordinal == 2


# -- along a corridor, from a door of a room one leaves ----------------------------------------------
@pytest.mark.parametrize(("text", "oid"), [
    ("going along the corridor from the kitchen door, the second plant you pass", 22),
    ("the first plant in the passage when you leave the kitchen", 21),
])
def test_an_ordinal_along_a_corridor(retriever, text, oid):
    assert _answer(retriever, text) == oid


# -- ordinals said otherwise than as an adjective -------------------------------------------------
@pytest.mark.parametrize(("text", "n"), [
    ("the bookshelf you would reach second from the corridor", 2),
    ("count the stools from the fridge, I want number three", 3),
    ("from the stove, pass the nearest stool and take the next one", 2),
    ("skip the first two stools from the fridge and go to the one after", 3),
    ("which bookshelf do you get to third when you walk in from the corridor?", 3),
])
def test_ordinals_said_as_an_adverb_a_number_or_a_skip(text, n):
    assert parse_instruction(text).ordinal == n


@pytest.mark.parametrize("text", [
    "I want to sit down for a second on the stool",
    "give me a second, then the desk",
    "the stool beside the cooker",
])
def test_words_that_are_no_ordinal(text):
    assert (parse_instruction(text).ordinal or 1) == 1


@pytest.mark.parametrize(("text", "oid"), [
    ("the bookshelf you would reach second from the corridor", 33),
    ("count the stools from the fridge, I want number three", 11),
    ("from the stove, pass the nearest stool and take the next one", 12),
    ("which bookshelf do you get to third when you walk in from the corridor?", 32),
])
def test_ordinals_said_otherwise_are_counted(retriever, text, oid):
    assert _answer(retriever, text) == oid


# -- any object counted along the way in -----------------------------------------------------------
def test_the_nth_thing_of_any_kind_from_the_way_in(retriever):
    assert _answer(retriever, "walking into the office from the corridor, the third thing you reach") == 33


# -- a sentence that points back at the goal is not a new goal -------------------------------------
@pytest.mark.parametrize("text", [
    "Which stool is the second one from the fridge? Go there.",
    "the third bookshelf from the corridor door. Take me to it please",
    "Starting at the stove, find the second stool. That is the one I want.",
])
def test_a_sentence_pointing_back_at_the_goal_is_the_same_goal(text):
    goals = parse_goals(text)
    assert len(goals) == 1 and goals[0].ordinal is not None and goals[0].ordinal > 1


# -- a door named by the room the candidates stand in is that room's own door ---------------------
@pytest.mark.parametrize(("text", "oid"), [
    ("the second bookshelf from the entrance to the office", 33),
    ("the third bookshelf from the office door", 32),
    ("counting from the office door, the second bookshelf", 33),
])
def test_a_door_named_by_the_candidates_own_room_is_its_door(retriever: Retriever, text: str, oid: int) -> None:
    assert _answer(retriever, text) == oid


@needs_spacy
def test_a_door_of_the_room_in_a_parsed_sentence(retriever: Retriever) -> None:
    assert _answer(retriever, "the second bookshelf in from the doorway of the office") == 33


@pytest.mark.parametrize(("text", "oid"), [
    ("the bookshelf furthest from the corridor door", 32),
    ("the plant furthest from the kitchen door", 22),
    ("the bookshelf furthest away from the entrance to the office", 32),
])
def test_farthest_from_a_door_reverses_the_order_from_the_way_in(retriever: Retriever, text: str, oid: int) -> None:
    assert _answer(retriever, text) == oid


# -- "nearest the X door" is the first met from that door, as "furthest from" is the last --------
@pytest.mark.parametrize(("text", "oid"), [
    ("the bookshelf nearest the corridor door", 31),
    ("the plant closest to the kitchen door", 21),
    ("take me to the bookshelf that is nearest to the office door", 31),
])
def test_nearest_a_door_is_the_first_from_the_way_in(retriever: Retriever, text: str, oid: int) -> None:
    assert _answer(retriever, text) == oid
    assert not parse_instruction(text).unknown_words
