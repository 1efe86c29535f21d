""""Corner" names a shape only before the object it shapes ("the corner sofa", "a corner desk");
"in the corner", "the corner of the room" say where a thing stands and must not refuse a plant
or a lamp for not being L-shaped. Sentences written for these tests."""

from __future__ import annotations

import pytest

from capnav.retrieval.query import parse_instruction


@pytest.mark.parametrize("text", ["the pot plant in the corner", "the lamp in the corner of the bedroom",
                                  "the chair tucked into the far corner"])
def test_a_corner_one_stands_in_is_no_shape(text: str) -> None:
    q = parse_instruction(text)
    assert "L-shaped" not in q.shapes, vars(q)


@pytest.mark.parametrize("text", ["the corner sofa", "the grey corner desk in the office"])
def test_a_corner_piece_is_l_shaped(text: str) -> None:
    q = parse_instruction(text)
    assert "L-shaped" in q.shapes, vars(q)
