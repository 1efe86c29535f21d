"""Requests by activity where no furniture is named: the activity (its verbs, the things handled)
reaches the furniture that serves it, the activity may imply the room (making tea: the kitchen, so
the kitchen sink before the bathroom sink), a thing handled that no furniture is made for is put
down on a surface, and a place said with an adjective ("a cosy place") is described by it.

The activities, sentences and scenes are written for these tests (none from a development set)."""

from __future__ import annotations

import pytest

from capnav.language import create_embedder
from capnav.language.purpose import activity_room, explain_activity, is_placing, split_activity
from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import grid_with_wall, make_obj, offline_retriever

KITCHEN_SINK, BATH_SINK, WASHER = 1, 5, 8
NIGHTSTAND, ARMCHAIR, DESK, LAMP = 13, 16, 18, 19


@pytest.fixture(scope="module")
def emb():  # type: ignore[no-untyped-def]
    return create_embedder("minilm")


@pytest.fixture(scope="module")
def kitchen_and_bathroom() -> Retriever:
    objs = [  # kitchen left of the wall, bathroom right of it
        make_obj(KITCHEN_SINK, "sink", (1.0, 0.5), (0.6, 0.5, 0.9), (200, 200, 200)),
        make_obj(2, "stove", (2.2, 0.5), (0.6, 0.6, 0.9), (40, 40, 40)),
        make_obj(3, "refrigerator", (0.5, 5.5), (0.7, 0.7, 1.8), (230, 230, 230)),
        make_obj(4, "counter", (3.0, 0.5), (1.0, 0.6, 0.9), (120, 90, 60)),
        make_obj(BATH_SINK, "sink", (5.0, 0.5), (0.5, 0.4, 0.9), (210, 210, 210)),
        make_obj(6, "toilet", (6.5, 0.5), (0.4, 0.6, 0.8), (240, 240, 240)),
        make_obj(7, "bathtub", (7.5, 5.0), (0.8, 1.7, 0.6), (235, 235, 235)),
        make_obj(WASHER, "washing machine", (5.2, 5.8), (0.6, 0.6, 0.85), (220, 220, 220)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


@pytest.fixture(scope="module")
def bedroom_and_study() -> Retriever:
    objs = [  # bedroom left of the wall, a study with a reading corner right of it
        make_obj(11, "bed", (1.5, 2.0), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(12, "wardrobe", (0.5, 6.0), (1.0, 0.6, 2.0), (120, 90, 60)),
        make_obj(NIGHTSTAND, "nightstand", (2.7, 0.8), (0.45, 0.4, 0.55), (150, 110, 70)),
        make_obj(14, "dresser", (3.0, 6.2), (1.0, 0.5, 0.9), (150, 110, 70)),
        make_obj(15, "bookshelf", (8.4, 6.3), (0.9, 0.35, 1.8), (90, 60, 40)),
        make_obj(ARMCHAIR, "armchair", (6.0, 5.5), (0.8, 0.8, 0.9), (170, 50, 50)),
        make_obj(17, "sofa", (6.5, 0.8), (2.0, 0.9, 0.8), (60, 60, 140)),
        make_obj(DESK, "desk", (8.3, 3.0), (1.2, 0.6, 0.75), (90, 60, 40)),
        make_obj(LAMP, "lamp", (7.0, 6.3), (0.3, 0.3, 1.5), (230, 230, 220)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))


# -- the parts of an activity ---------------------------------------------------------------------

@pytest.mark.parametrize(("activity", "parts"), [
    ("rinse a cup before making tea", ["rinse a cup", "making tea"]),
    ("wash my face before i go to bed", ["wash my face", "i go to bed"]),
    ("scrub the pan after cooking", ["scrub the pan", "cooking"]),
    ("sleep", ["sleep"]),
])
def test_an_activity_splits_into_the_act_and_what_it_is_for(activity: str, parts: list[str]) -> None:
    assert split_activity(activity) == parts


@pytest.mark.parametrize(("activity", "room"), [
    ("rinse a cup before making tea", "kitchen"),
    ("scrub the pan after cooking supper", "kitchen"),
    ("chop some onions", "kitchen"),
    ("take a shower", "bathroom"),
    ("have a soak in the tub", "bathroom"),
    ("wash my face before i brush my teeth", "bathroom"),
])
def test_an_activity_implies_its_room(emb, activity: str, room: str) -> None:  # type: ignore[no-untyped-def]
    assert activity_room(activity, emb) == room


@pytest.mark.parametrize("activity", ["hang up my coat", "put my drink down", "keep my socks"])
def test_an_activity_of_any_room_implies_none(emb, activity: str) -> None:  # type: ignore[no-untyped-def]
    assert activity_room(activity, emb) is None


@pytest.mark.parametrize(("activity", "placing"), [
    ("leave my keys", True), ("leave the phone", True), ("charge my phone", True),
    ("recharge my laptop overnight", True), ("put the towels on a wash cycle", False),
    ("rinse a cup", False), ("leave the kitchen", False), ("read a book", False),
    ("make a phone call", False), ("charge my phone overnight", True),
    ("my laptop is running low, charge it", True), ("the cat is hungry, feed it", False),
])
def test_a_thing_handled_that_no_furniture_is_made_for_is_put_down(emb, activity: str,
                                                                    placing: bool) -> None:  # type: ignore[no-untyped-def]
    assert is_placing(activity, emb) is placing


def test_an_idiom_of_a_light_verb_is_read_by_what_it_means() -> None:
    assert explain_activity("do the dishes").endswith("wash dishes")
    assert explain_activity("doing the dishes").endswith("wash dishes")
    assert explain_activity("hang up my coat") == "hang up my coat"  # no light verb: its own words


# -- end to end on the scenes --------------------------------------------------------------------

@pytest.mark.parametrize(("text", "oid"), [
    ("I need to rinse a cup before making tea", KITCHEN_SINK),
    ("somewhere to rinse the saucepan after cooking", KITCHEN_SINK),
    ("where can I wash my face before I brush my teeth", BATH_SINK),
    ("where do I put the laundry on a wash cycle", WASHER),
    ("these sheets need a hot wash, where can I put them on a cycle?", WASHER),
    ("the bath towels need washing, where can I put them on a cycle?", WASHER),
    ("where can I do the dishes", KITCHEN_SINK),
])
def test_the_activity_reaches_the_furniture_in_its_room(kitchen_and_bathroom: Retriever, text: str,
                                                        oid: int) -> None:
    res = kitchen_and_bathroom.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "oid"), [
    ("somewhere to charge my phone by where I sleep", NIGHTSTAND),
    ("where can I leave my glasses next to where I sleep", NIGHTSTAND),
    ("a cosy place to read", ARMCHAIR),
    ("I'd like a comfy spot to curl up with a novel", ARMCHAIR),
    ("somewhere to write my postcards", DESK),
    ("somewhere comfy to read", ARMCHAIR),
    ("my laptop is running low, where can I charge it next to where I sleep?", NIGHTSTAND),
])
def test_the_activity_reaches_the_furniture_made_for_it(bedroom_and_study: Retriever, text: str,
                                                        oid: int) -> None:
    res = bedroom_and_study.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


@pytest.mark.parametrize(("text", "category"), [
    ("the bath mat", None), ("the bed linen", None), ("the bath", "bathtub"), ("the lamp shade", "lamp"),
])
def test_a_compound_on_a_category_word_names_another_thing(text: str, category: str | None) -> None:
    # WordNet's compounds whose first word is a category word ("bath towel") are another object;
    # a part of the category's object ("lamp shade") is still that object.
    assert parse_instruction(text, use_parser=False).category == category


def test_a_place_adjective_is_no_unknown_target(emb) -> None:  # type: ignore[no-untyped-def]
    q = parse_instruction("a cosy place to read", emb)
    assert q.purpose == "read" and q.category is not None and not q.unknown_words
