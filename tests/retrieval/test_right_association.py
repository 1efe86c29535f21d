"""A phrase right after the target's noun describes the target even where the parser hung it on the
verb ("navigate to the houseplant with the yellow pot": spaCy's small model reads "with the
yellow pot" as how to navigate, and the colour was dropped as no word of the target's). Phrases
of the motion itself (where it goes, what for, when) stay on the verb. Sentences and scene
written for these tests (the failure was seen on fresh benchmark seed 700003), none from the
development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse as parse_mod
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever

needs_spacy = pytest.mark.skipif(parse_mod.load_parser() is None, reason="spaCy's English pipeline is not installed")


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "plant", (1.0, 1.0), (0.5, 0.5, 1.1), (225, 190, 40)),  # yellow pot
        make_obj(2, "plant", (3.0, 5.5), (0.6, 0.6, 1.2), (235, 235, 230)),  # white pot
        make_obj(3, "plant", (7.0, 1.5), (0.4, 0.4, 0.9), (46, 120, 60)),  # green pot
        make_obj(4, "lamp", (2.0, 3.0), (0.4, 0.4, 1.5), (30, 30, 30)),
        make_obj(5, "lamp", (6.5, 5.0), (0.4, 0.4, 1.5), (60, 140, 60)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


@needs_spacy
@pytest.mark.parametrize(("text", "oid", "colour"), [
    ("I'd like to go to the houseplant in the white pot, please.", 2, "white"),
    ("Would you navigate to the houseplant with the yellow pot?", 1, "yellow"),
    ("could you take me over to the lamp with the green shade", 5, "green"),
    ("move to the lamp with the black shade", 4, "black"),
])
def test_a_phrase_after_the_target_describes_it(retriever: Retriever, text: str, oid: int, colour: str) -> None:
    assert colour in parse_instruction(text).colors
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@needs_spacy
@pytest.mark.parametrize(("text", "colour"), [
    ("I want to get to the armchair with the red cushions", "red"),
    ("bring me to the cabinet with the blue doors", "blue"),
])
def test_the_colour_after_the_noun_is_the_targets(text: str, colour: str) -> None:
    q = parse_instruction(text)
    assert colour in q.colors, q


@needs_spacy
@pytest.mark.parametrize("text", [
    "go to the sofa for a green tea",  # what the trip is for
    "once in a blue moon I go to the sofa",  # before the target
    "go to the sofa, with a green face I said",  # after a comma
])
def test_phrases_of_the_motion_stay_on_the_verb(text: str) -> None:
    q = parse_instruction(text)
    assert q.category == "sofa" and q.colors == [], q
