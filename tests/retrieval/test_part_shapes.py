"""A shape said of a part is the part's, not the object's ("the armchair with rounded arms": the
arms are round, the armchair's footprint need not be): the map measures the whole footprint, not
its parts apart, so such a shape neither confirms nor refuses (as a part's material, issue 22 item
4). A shape said of the object itself still counts. Sentences and scenes written for this test."""

from __future__ import annotations

import pytest

from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever


@pytest.mark.parametrize(("text", "part", "shape"), [
    ("the armchair with rounded arms", "arms", "round"),
    ("a sofa that has a curved back", "back", "curved"),
    ("the stool with round legs", "legs", "round"),
    ("take me to the lamp with the circular base", "base", "round"),
])
def test_a_parts_shape_is_the_parts(text: str, part: str, shape: str) -> None:
    q = parse_instruction(text)
    assert shape not in q.shapes, (text, q.shapes)
    assert shape in q.part_shapes.get(part, []), (text, q.part_shapes)


def test_the_objects_own_shape_still_counts() -> None:
    for text in ("the round table", "the curved sofa with cushions", "a round stool with a red seat"):
        assert parse_instruction(text).shapes, text


def test_a_square_armchair_is_not_refused_for_its_round_arms() -> None:
    objs = [make_obj(1, "armchair", (1.0, 1.0), (0.9, 0.8, 0.8), (200, 190, 160)),
            make_obj(2, "bed", (6.0, 4.0), (1.6, 2.0, 0.5), (90, 60, 40))]
    r = offline_retriever(objs, grid_with_wall(-1, -1, 8, 6))
    res = r.query("the armchair with rounded arms")
    assert res.found and res.chosen is not None and res.chosen.id == 1, res.reason
