"""A story told in the past is no goal of its own, even when a sequence word ("and then") runs
through it: "he was reading on the sofa and then he went to the kitchen, I think he left his
glasses next to the fridge, could you go and look" asks for one place, the fridge. A story that
ends without asking but points back ("..., my phone must still be on it") asks for the object it
points at. Goals that are asked for ("the fridge and then the sofa", "I'd like to see the tv and
then the bed") stay two. Sentences and scene written for these tests (helper fresh22), none from
a development set or from benchmarks/own_phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_goals
from capnav.retrieval.sequence import query_goals
from language.synth import make_obj, offline_retriever

BED, FRIDGE, TV, SOFA, DESK = 1, 2, 3, 4, 5


@pytest.fixture(scope="module")
def flat() -> Retriever:
    objs = [
        make_obj(BED, "bed", (1.0, 5.5), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(FRIDGE, "refrigerator", (8.0, 0.5), (0.7, 0.7, 1.8), (230, 230, 230)),
        make_obj(TV, "tv", (4.5, 6.4), (1.2, 0.3, 0.7), (20, 20, 20)),
        make_obj(SOFA, "sofa", (4.5, 3.0), (2.0, 0.9, 0.8), (60, 60, 140)),
        make_obj(DESK, "desk", (7.5, 6.0), (1.2, 0.6, 0.75), (120, 90, 60)),
    ]
    return offline_retriever(objs)


@pytest.mark.parametrize(("text", "oid"), [
    ("my husband was reading on the sofa and then he went to the kitchen, I think he left his glasses "
     "next to the fridge, could you go and look", FRIDGE),
    ("we were watching the tv after dinner and then the dog ran off, I bet it is hiding under the desk, "
     "go and see", DESK),
    ("I was working at the desk all morning and then had a rest on the sofa, I reckon my pen rolled "
     "under the bed though, please check there", BED),
    ("the cat was asleep on the bed and then she jumped down, I guess she knocked my earring behind the tv, "
     "go and have a look", TV),
    # a thing the map does not hold, where it is or was lost; then a bare ask
    ("there's a wasp buzzing round behind the fridge, go and see", FRIDGE),
    ("my daughter lost a sock somewhere under the desk, can you go and check", DESK),
])
def test_a_past_story_with_then_is_one_goal(flat: Retriever, text: str, oid: int) -> None:
    goals = parse_goals(text)
    assert len(goals) == 1, [g.target_phrase for g in goals]
    res = query_goals(flat, text).results[0]
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "oid"), [
    ("after my shower I sat on the bed and read for an hour, my phone ought to be on it", BED),
    ("this morning I had my breakfast in front of the tv and worked at the desk, my mug must still be on it",
     DESK),
    # "got" is a form of a request verb ("get me to ..."), here told in the past by "I"
    ("when I got back from the shops I had a sit on the sofa, my keys could still be on it", SOFA),
])
def test_a_story_that_only_points_back_asks_for_what_it_points_at(flat: Retriever, text: str, oid: int) -> None:
    res = query_goals(flat, text).results[0]
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "oid"), [
    ("I had a snooze on the sofa after lunch, but what I'm after now is the fridge", FRIDGE),
    ("the kids were jumping on the bed all day and what I want is the desk", DESK),
])
def test_a_story_that_ends_by_naming_what_is_wanted(flat: Retriever, text: str, oid: int) -> None:
    res = query_goals(flat, text).results[0]
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize("text", [
    "go to the fridge and then the sofa",
    "I'd like to see the tv and then the bed",
    "could you take me to the desk, then to the bed",
])
def test_asked_goals_stay_several(text: str) -> None:
    assert len(parse_goals(text)) == 2


@pytest.mark.parametrize(("text", "left_out", "kept"), [
    ("we were having breakfast in the kitchen by the fridge and then I went up to the bedroom, I think I left "
     "my watch on the nightstand, go and get it", "kitchen", "nightstand"),
    ("I was reading on the sofa in the living room and after that I went into the study, my book is on the "
     "desk I reckon, fetch it for me", "living room", "desk"),
])
def test_a_story_keeps_the_last_room_it_reached(text: str, left_out: str, kept: str) -> None:
    from capnav.retrieval.query.parse import analyse

    goals = analyse(text, True)
    assert len(goals) == 1 and left_out not in goals[0].core and kept in goals[0].core, goals[0].core
