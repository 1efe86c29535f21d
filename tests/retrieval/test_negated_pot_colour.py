"""A negated colour picks out the one it excludes among the candidates (issue 22, negation): of
potted plants whose leaves are all green, "not the red one" means the plant in the red pot, so
the colour is judged on the pots when the whole plants' colours name every candidate alike.
Before, the negated colour was judged on the leaves, excluded every plant or none, and the plant
in the excluded pot was chosen. Scenes and sentences written for this test (helper lang25), none
from the development phrasings or the sets scored."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from language.synth import grid_with_wall, make_obj, offline_retriever
from retrieval.test_colour_shades import potted


@pytest.fixture(scope="module")
def three_pots() -> Retriever:
    objs = [potted(1, (1.0, 1.0), (60, 120, 50), (150, 30, 30)),    # green leaves, red pot
            potted(2, (3.0, 1.0), (60, 120, 50), (235, 235, 230)),  # green leaves, white pot
            make_obj(3, "bed", (7.0, 5.0), (1.6, 2.0, 0.5), (205, 200, 195))]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7))


@pytest.mark.parametrize(("text", "oid"), [
    ("the houseplant, not the red one", 2),
    ("a plant but not the white one", 1),
    ("the plant that isn't the red one", 2),
])
def test_a_negated_colour_is_judged_where_the_plants_differ(three_pots: Retriever, text: str, oid: int) -> None:
    res = three_pots.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_a_negated_colour_every_plant_shows_excludes_none_apart(three_pots: Retriever) -> None:
    # "not the green one" where every plant's leaves are green and no pot is: nothing to exclude
    # apart, so both plants are excluded as green (the leaves) and the request is not found.
    res = three_pots.query("the plant, not the green one")
    assert not res.found, res.reason
