"""An object one walks past on the way ("go past the sofa and stop at the bookshelf behind it",
"walk past the bed to the lamp") is passed, not the goal: the goal is the object named after it.
"The lamp past the sofa" (the thing named first) keeps its target. Sentences written for these
tests, none from the development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval.query import parse_instruction


@pytest.mark.parametrize(("text", "target"), [
    ("go past the sofa and stop at the bookshelf behind it", "bookshelf"),
    ("walk past the bed and go to the lamp", "lamp"),
    ("go past the sofa to the bookshelf", "bookshelf"),
    ("head past the kitchen table and on to the fridge", "refrigerator"),
    ("drive past the tv then stop by the armchair", "armchair"),
])
def test_an_object_walked_past_is_not_the_goal(text: str, target: str) -> None:
    q = parse_instruction(text)
    assert q.category == target, vars(q)


def test_the_thing_named_first_keeps_its_target() -> None:
    q = parse_instruction("the lamp just past the sofa")
    assert q.category == "lamp", vars(q)
