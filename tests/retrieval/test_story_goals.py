"""Story-like requests with pronouns and several goals: where a thing was left or put is the
goal when the thing is no object of the map ("she left her bag by the bed, go there": the bed),
the object itself when it is one ("we bought a plant and put it next to the fridge, go look at
it": that plant); "it" and "there" point back at it, and a goal that only points back is the same
goal, not a second one. A verb of leaving a room ("she left the kitchen") places nothing.
Sentences and the scene are written for these tests (none from a development set)."""

from __future__ import annotations

import pytest

from capnav.language.purpose import is_placing
from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_goals
from capnav.retrieval.sequence import query_goals
from language.synth import make_obj, offline_retriever

BED, NIGHTSTAND, FRIDGE, PLANT_BY_FRIDGE, PLANT_FAR, TV, SOFA, COUNTER = 1, 2, 3, 4, 5, 6, 7, 8


@pytest.fixture(scope="module")
def flat() -> Retriever:
    objs = [
        make_obj(BED, "bed", (1.0, 5.5), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(NIGHTSTAND, "nightstand", (2.3, 6.3), (0.45, 0.4, 0.55), (150, 110, 70)),
        make_obj(FRIDGE, "refrigerator", (8.0, 0.5), (0.7, 0.7, 1.8), (230, 230, 230)),
        make_obj(PLANT_BY_FRIDGE, "plant", (8.0, 1.4), (0.4, 0.4, 0.9), (40, 140, 40)),
        make_obj(PLANT_FAR, "plant", (0.5, 0.5), (0.4, 0.4, 0.9), (40, 140, 40)),
        make_obj(TV, "tv", (4.5, 6.4), (1.2, 0.3, 0.7), (20, 20, 20)),
        make_obj(SOFA, "sofa", (4.5, 3.0), (2.0, 0.9, 0.8), (60, 60, 140)),
        make_obj(COUNTER, "counter", (6.8, 0.5), (1.2, 0.6, 0.9), (120, 90, 60)),
    ]
    return offline_retriever(objs)


@pytest.mark.parametrize(("text", "oid"), [
    ("she left her bag by the bed, go there", BED),
    ("my son left his scarf beside the tv, take me there", TV),
    ("grandpa laid his walking stick next to the sofa, can you go there?", SOFA),
    ("we bought a new plant and put it next to the fridge, go look at it", PLANT_BY_FRIDGE),
])
def test_where_a_thing_was_left_is_the_goal(flat: Retriever, text: str, oid: int) -> None:
    seq = query_goals(flat, text)
    assert len(seq.goals) == 1, seq.goals
    res = seq.results[0]
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_a_goal_that_only_points_back_is_the_same_goal(flat: Retriever) -> None:
    goals = parse_goals("put it next to the fridge, then go look at it")
    assert len(goals) == 1, [g.text for g in goals]
    seq = query_goals(flat, "put it next to the fridge, then go look at it")
    assert seq.results[0].chosen is not None and seq.results[0].chosen.id == FRIDGE, seq.results[0].reason


def test_a_story_then_a_second_goal_keeps_both_in_order(flat: Retriever) -> None:
    seq = query_goals(flat, "I left my keys on the counter, go there and then to the sofa")
    assert [r.chosen.id if r.chosen else None for r in seq.results] == [COUNTER, SOFA], seq.to_dict()
    out = seq.to_dict()
    assert out["found"] and out["chosen"] and len(out["goals"]) == 2


def test_leaving_a_room_places_nothing() -> None:
    assert is_placing("left the kitchen") is False
    assert is_placing("left my keys") is True
