"""A side of a landmark ("the chair to the left of the desk", "the lamp on the right-hand side of
the sofa") is a relation to that landmark as the speaker sees it: from the robot, the one beside
the landmark on that side; without a viewpoint, the ones beside it. Before, the side was read as
a side of a room's way in and the landmark was dropped. Scene and sentences written for these
tests, none from the development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "desk", (2.0, 3.0), (1.2, 0.6, 0.75), (120, 80, 50)),
        make_obj(2, "chair", (1.0, 3.0), (0.5, 0.5, 0.9), (90, 90, 90)),  # left of the desk seen from y < 3
        make_obj(3, "chair", (3.0, 3.0), (0.5, 0.5, 0.9), (90, 90, 90)),  # right of it
        make_obj(4, "chair", (7.0, 5.5), (0.5, 0.5, 0.9), (90, 90, 90)),  # far from the desk
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=5.0, door=(2.5, 3.5)))


@pytest.mark.parametrize(("text", "relation"), [
    ("the chair to the left of the desk", "left of"),
    ("take me to the chair on the right-hand side of the desk", "right of"),
    ("the chair on the left side of the desk", "left of"),
])
def test_a_side_of_a_landmark_is_a_relation(text: str, relation: str) -> None:
    q = parse_instruction(text)
    assert q.relation == relation and q.anchor_category == "desk" and q.side is None, q


@pytest.mark.parametrize(("text", "robot", "oid"), [
    ("the chair to the left of the desk", (2.0, 0.5), 2),
    ("the chair to the right of the desk", (2.0, 0.5), 3),
    ("the chair to the left of the desk", (2.0, 6.0), 3),  # seen from the other side
])
def test_the_side_is_seen_from_the_robot(retriever: Retriever, text: str, robot: tuple[float, float],
                                         oid: int) -> None:
    res = retriever.query(text, robot_xy=robot)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_without_a_viewpoint_the_landmark_still_counts(retriever: Retriever) -> None:
    res = retriever.query("the chair to the left of the desk")
    assert res.found and res.chosen is not None and res.chosen.id in (2, 3), res.reason
    assert "needs a viewpoint" in res.reason
