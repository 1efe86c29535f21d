"""A relation between two of one category: the landmark said by a stand-in for the target's own
category ("the sink opposite the black one") is another instance, picked by its own words, and
"across A from B" / "facing B across A" puts the target and B on either side of A. The words of
the stand-in are the landmark's, not the target's. Sentences and scene written for these tests,
none from the development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import ACROSS, parse_instruction
from capnav.retrieval.query import parse as parse_mod
from language.synth import grid_with_wall, make_obj, offline_retriever

needs_spacy = pytest.mark.skipif(parse_mod.load_parser() is None, reason="spaCy's English pipeline is not installed")
RED, GREEN, YELLOW, BLACK_SINK, WHITE_SINK, WHITE_LAMP, BLUE_LAMP = 2, 3, 4, 5, 6, 7, 8


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "coffee table", (3.0, 3.0), (1.0, 0.6, 0.45), (120, 80, 50)),
        make_obj(RED, "armchair", (3.0, 1.9), (0.8, 0.8, 0.9), (200, 40, 40)),  # south of the table
        make_obj(GREEN, "armchair", (3.0, 4.1), (0.8, 0.8, 0.9), (60, 140, 60)),  # north, across it
        make_obj(YELLOW, "armchair", (4.2, 2.2), (0.8, 0.8, 0.9), (230, 200, 40)),  # beside the red one
        make_obj(BLACK_SINK, "sink", (7.0, 0.5), (0.6, 0.5, 0.9), (20, 20, 20)),
        make_obj(WHITE_SINK, "sink", (7.0, 5.5), (0.6, 0.5, 0.9), (240, 240, 240)),
        make_obj(WHITE_LAMP, "lamp", (0.5, 5.5), (0.4, 0.4, 1.6), (240, 240, 230)),
        make_obj(BLUE_LAMP, "lamp", (0.5, 0.5), (0.4, 0.4, 1.6), (40, 60, 160)),
        make_obj(9, "sofa", (0.5, 3.0), (0.9, 2.0, 0.8), (120, 120, 120)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7))


@pytest.mark.parametrize(("text", "oid"), [
    ("the basin opposite the black one", WHITE_SINK),
    ("the sink across from the white one", BLACK_SINK),
    ("the lamp next to the blue one", WHITE_LAMP),
    ("the armchair across the coffee table from the red one", GREEN),
    ("the armchair facing the red one over the coffee table", GREEN),
    ("the lamp on the other side of the sofa from the blue one", WHITE_LAMP),
])
def test_a_stand_in_landmark_is_another_of_the_targets_kind(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@needs_spacy
@pytest.mark.parametrize(("text", "oid"), [
    ("which armchair is directly across the coffee table from the green one", RED),
    ("could you take me to the armchair that sits across the coffee table from the red one", GREEN),
])
def test_across_in_a_parsed_sentence(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_the_stand_ins_words_are_the_landmarks() -> None:
    q = parse_instruction("the armchair across the coffee table from the red one")
    assert q.relation == ACROSS and q.colors == [] and q.anchor_category == "armchair"
    assert q.anchor2_category == "coffee table"
    q = parse_instruction("the sink opposite the black one")
    assert q.colors == [] and q.anchor_category == "sink" and q.anchor_phrase == "black one"
