"""Words of height ("the tall lamp", "the short cactus", "the lowest table") compare the mapped
heights of a category, not its volumes: a slim floor lamp is the tall one beside a squat, wide
table lamp that fills more space. Scene and sentences written for these tests, none from the
development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "lamp", (1.0, 1.0), (0.25, 0.25, 1.7), (230, 230, 220)),  # slim and tall
        make_obj(2, "lamp", (3.0, 5.5), (0.9, 0.9, 0.6), (230, 230, 220)),  # wide and low: more volume
        make_obj(3, "plant", (6.0, 1.0), (0.3, 0.3, 1.4), (60, 120, 60)),
        make_obj(4, "plant", (7.5, 5.0), (0.9, 0.9, 0.7), (60, 120, 60)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


@pytest.mark.parametrize(("text", "oid"), [
    ("take me to the tall lamp", 1),
    ("the short lamp please", 2),
    ("go to the tallest lamp", 1),
    ("the lowest of the lamps", 2),
    ("the lamp that is shorter", 2),
    ("could you find the lanky plant", 3),
    ("the stumpy plant", 4),
    ("the biggest lamp", 2),  # size, not height: the wide one fills more space
])
def test_height_words_compare_heights(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_a_size_word_keeps_the_volume() -> None:
    assert parse_instruction("the big lamp").size_axis is None
    assert parse_instruction("the tall lamp").size_axis == "height"
