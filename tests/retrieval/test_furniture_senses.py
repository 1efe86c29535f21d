"""Everyday and regional names of furniture through WordNet, not a list of regional words: a word
whose first sense is another thing but which WordNet also has as one category's furniture (Irish
and British "press": WordNet's wardrobe, "clothes press", with "closet" whose first sense is the
cupboard) is that category where an object's name stands; a name WordNet lacks ("dunny",
"khazi") is said to be unknown and never read as a lookalike ("khaki"). Sentences and scenes
written for these tests."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever

KITCHEN_CABINET, WARDROBE, TOILET = 4, 6, 8


@pytest.fixture(scope="module")
def flat() -> Retriever:
    objs = [  # a kitchen left of the wall, a bedroom with a toilet corner right of it
        make_obj(1, "sink", (1.0, 0.5), (0.6, 0.5, 0.9), (200, 200, 200)),
        make_obj(2, "stove", (2.2, 0.5), (0.6, 0.6, 0.9), (40, 40, 40)),
        make_obj(3, "refrigerator", (0.5, 5.5), (0.7, 0.7, 1.8), (230, 230, 230)),
        make_obj(KITCHEN_CABINET, "cabinet", (3.0, 6.3), (1.0, 0.5, 0.9), (150, 110, 70)),
        make_obj(5, "bed", (6.5, 3.0), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(WARDROBE, "wardrobe", (8.4, 6.2), (1.0, 0.6, 2.0), (120, 90, 60)),
        make_obj(7, "nightstand", (7.6, 1.6), (0.45, 0.4, 0.55), (150, 110, 70)),
        make_obj(TOILET, "toilet", (5.0, 0.5), (0.4, 0.6, 0.8), (240, 240, 240)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


@pytest.mark.parametrize(("text", "category"), [
    ("the kitchen press", "wardrobe"), ("go to the presses in the kitchen", "wardrobe"),
    ("the old press in the hall", "wardrobe"), ("the top bunk", "bed"),
])
def test_a_furniture_sense_names_its_category(text: str, category: str) -> None:
    q = parse_instruction(text, use_parser=False)
    assert q.category == category, q.to_dict()
    assert any("WordNet" in n for n in q.notes), q.notes


def test_the_press_may_be_the_cupboard_its_synonym_closet_names() -> None:
    assert parse_instruction("the kitchen press", use_parser=False).category_alternatives.get("cabinet", 0) > 0


@pytest.mark.parametrize("text", ["press the button twice", "a bar of soap", "stand up please"])
def test_the_word_s_other_senses_stay_other(text: str) -> None:
    assert parse_instruction(text, use_parser=False).category is None


@pytest.mark.parametrize("text", ["where's the khazi?", "take me to the dunny", "the bog please"])
def test_a_name_wordnet_lacks_is_unknown_not_a_lookalike(text: str) -> None:
    q = parse_instruction(text, use_parser=False)
    assert q.category is None and not q.colors, q.to_dict()
    assert any("known to the lexicon" in n for n in q.notes), q.notes


def test_the_kitchen_press_is_the_kitchen_cupboard(flat: Retriever) -> None:
    res = flat.query("the kitchen press")
    assert res.found and res.chosen is not None and res.chosen.id == KITCHEN_CABINET, res.reason


def test_the_bedroom_press_is_the_wardrobe(flat: Retriever) -> None:
    res = flat.query("the press in the bedroom")
    assert res.found and res.chosen is not None and res.chosen.id == WARDROBE, res.reason


def test_an_unknown_name_is_not_found_and_says_why(flat: Retriever) -> None:
    res = flat.query("where's the khazi?")
    assert not res.found, res.reason
    assert "known to the lexicon" in res.reason, res.reason
