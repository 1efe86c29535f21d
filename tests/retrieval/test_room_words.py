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
from language.synth import bedroom_and_lounge


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    return bedroom_and_lounge()


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
