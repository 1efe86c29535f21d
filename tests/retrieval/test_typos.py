"""Misspelt words are read by one rule, an edit distance to the words the parser knows (every
category form WordNet gives, colours, rooms, keywords) with the first letter kept, never by a
list of misspellings; real English words near a known one are not typos. Sentences written for
these tests."""

from __future__ import annotations

import pytest

from capnav.retrieval.query import parse_instruction
from capnav.retrieval.query.tokens import typo_distance


@pytest.mark.parametrize(("text", "category", "extra"), [
    ("the succlent by the tv", "plant", {"anchor_category": "tv"}),  # a WordNet form, one letter dropped
    ("the ottmoan in the lounge", "ottoman", {"room": "living room"}),  # two letters swapped
    ("the wardrboe in the bdroom", "wardrobe", {"room": "bedroom"}),
    ("the cupbaord in the bathroom", "cabinet", {"room": "bathroom"}),
    ("the frigde nex to the stove", "refrigerator", {"anchor_category": "stove", "relation": "next to"}),
    ("the gren lamp", "lamp", {"colors": ["green"]}),
    ("the wite armchiar", "armchair", {"colors": ["white"]}),
])
def test_a_misspelt_word_is_read_as_the_word_it_nears(text, category, extra):
    q = parse_instruction(text, use_parser=False)
    assert q.category == category, q
    for k, v in extra.items():
        assert getattr(q, k) == v, (k, getattr(q, k))


@pytest.mark.parametrize(("text", "category"), [
    ("put the sheets on the bed", "bed"),  # "sheets" is a word, not "seats"
    ("the wellies in the hall", None),  # first letters differ: no "tellies"
    ("the lamp, its charger is charging", "lamp"),
    ("the store cupboard", "cabinet"),  # "store" is no "stove"
])
def test_real_words_near_a_known_word_are_no_typos(text, category):
    assert parse_instruction(text, use_parser=False).category == category


def test_the_first_object_named_is_the_target_typo_or_not():
    q = parse_instruction("the nightstnd beside the lamp", use_parser=False)
    assert q.category == "nightstand" and q.anchor_category == "lamp"


def test_the_distance_grows_with_the_word():
    assert typo_distance("sofa") == 1 and typo_distance("wardrobe") == 2
