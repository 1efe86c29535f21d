"""A noun compound's head is its last noun: "the desk chair" is a chair beside or without a desk,
never the desk; the category word before the head says what kind. Sentences and scenes written
for these tests."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import make_obj, offline_retriever


@pytest.mark.parametrize(("text", "category"), [
    ("the swivel desk chair", "chair"),
    ("a tv cabinet in the lounge", "cabinet"),
    ("my little bed lamp", "lamp"),
    ("the kitchen counter stool by the window", "stool"),
    ("the coffee table lamp", "lamp"),
    ("the desk beside the chair", "desk"),  # two nouns apart: the first named is the target
])
def test_the_last_noun_of_a_compound_is_the_target(text: str, category: str) -> None:
    assert parse_instruction(text, use_parser=False).category == category


def _retriever(objs: list) -> Retriever:  # type: ignore[type-arg]
    return offline_retriever(objs)


def test_a_compound_reaches_its_head_not_its_modifier() -> None:
    r = _retriever([make_obj(1, "desk", (1.0, 1.0), (1.2, 0.6, 0.75), (90, 60, 40)),
                    make_obj(2, "chair", (1.0, 1.8), (0.5, 0.5, 0.9), (30, 30, 30)),
                    make_obj(3, "bed", (5.0, 4.0), (1.6, 2.0, 0.5), (200, 200, 230))])
    res = r.query("go to the desk chair please")
    assert res.found and res.chosen is not None and res.chosen.id == 2, res.reason


def test_a_compound_whose_head_is_absent_is_not_answered_by_its_modifier() -> None:
    r = _retriever([make_obj(1, "desk", (1.0, 1.0), (1.2, 0.6, 0.75), (90, 60, 40)),
                    make_obj(3, "bed", (5.0, 4.0), (1.6, 2.0, 0.5), (200, 200, 230))])
    res = r.query("take me to the office chair by the desk")
    assert not res.found, res.reason
