"""Room words come from WordNet's rooms (the lexicon's ``rooms``), not from a hand list: "the
guest room", "the kitchenette", "the powder room", "the front room" and a room named after who
sleeps in it ("the kid's room", "the children's room") are rooms, never unknown words. Scene and
sentences written for these tests, none from the development phrasings."""

from __future__ import annotations

import pytest

from capnav.language.context import ROOM_SYNONYMS, room_ending, room_starting
from capnav.language.lexicon import load_lexicon
from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "bed", (1.0, 1.5), (1.6, 2.0, 0.5), (200, 200, 210)),
        make_obj(2, "lamp", (2.5, 4.5), (0.3, 0.3, 1.5), (230, 230, 220)),
        make_obj(3, "sofa", (6.5, 1.0), (2.0, 0.9, 0.8), (90, 90, 100)),
        make_obj(4, "tv", (6.5, 5.5), (1.0, 0.2, 0.6), (20, 20, 20)),
        make_obj(5, "lamp", (5.0, 4.5), (0.3, 0.3, 1.5), (230, 230, 220)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


@pytest.mark.parametrize(("text", "oid"), [
    ("take me to the lamp in the guest room", 2),
    ("the lamp in the kid's room please", 2),
    ("go to the lamp in the childrens room", 2),
    ("the guestroom lamp", 2),
    ("find the lamp in the front room", 5),
])
def test_wordnet_room_words_choose_the_room(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "room"), [
    ("the sink in the powder room", "bathroom"),
    ("the chair in the kitchenette", "kitchen"),
    ("the plant in the vestibule", "hallway"),
    ("the bed in the kids' room", "bedroom"),
    ("the lamp in the master bedroom", "bedroom"),
    ("the armchair in the lounge", "living room"),  # a room word WordNet files as a sofa first
])
def test_room_words_parse(text: str, room: str) -> None:
    q = parse_instruction(text)
    assert q.room == room and not q.unknown_words, vars(q)


def test_room_names_of_several_tokens_are_found_either_way() -> None:
    toks = ["the", "lamp", "in", "the", "kid", "'s", "room"]
    assert room_starting(toks, 4) == ("bedroom", 3)
    assert room_ending(toks, 7) == ("bedroom", 3)
    assert room_starting(toks, 1) is None


def test_room_words_are_not_category_forms_or_names() -> None:
    lex = load_lexicon()
    assert lex.rooms, "the shipped lexicon has no room words"
    assert not set(lex.rooms) & set(lex.forms)  # "lavatory" asks for the toilet, not the room
    assert "john" not in ROOM_SYNONYMS and "closet" not in ROOM_SYNONYMS and "chamber" not in ROOM_SYNONYMS
    assert set(ROOM_SYNONYMS.values()) <= {"kitchen", "bedroom", "bathroom", "living room", "office", "hallway"}
