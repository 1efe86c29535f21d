"""Requests by purpose rank the furniture made for the activity before furniture that merely
allows it, and a request naming what is kept somewhere reaches the furniture that holds it.

The activities and their answers are written here for this test (not package data, and none
from the development phrasings); each answer is the category whose own definition states the
activity as its use."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.language import create_embedder
from capnav.language.purpose import GlossIndex, find_activity, match_purpose, purpose_categories, stated_purpose

ACTIVITIES: dict[str, set[str]] = {
    "write a letter": {"desk"}, "sleep": {"bed"}, "hang up my coat": {"wardrobe"},
    "store my socks": {"dresser", "wardrobe"}, "keep my books": {"bookshelf"}, "take a bath": {"bathtub"},
    "cook pasta": {"stove"}, "keep the milk cold": {"refrigerator"}, "wash the dishes": {"sink"},
    "rest my feet": {"ottoman"}, "watch a film": {"tv"}, "brush my teeth": {"sink"}, "eat breakfast": {"table"},
    "sit down": {"chair", "armchair", "sofa", "stool", "ottoman"}, "lie down": {"bed"},
    "do the laundry": {"washing machine"}, "have a nap": {"bed"}, "put my feet up": {"ottoman"},
    "fold my jumpers away": {"dresser", "wardrobe"}, "pee": {"toilet"},
    "put my drink down": {"coffee table", "nightstand", "table"}, "do my homework": {"desk"},
    "read by lamplight": {"lamp"}, "take a shower": {"bathtub"}, "put away the plates": {"cabinet"},
    "hang my dressing gown": {"wardrobe"}, "have a wash": {"sink", "bathtub"}, "heat up soup": {"stove"},
    "keep the butter cool": {"refrigerator"}, "lie down for a bit": {"bed"}, "stack my novels": {"bookshelf"},
    "wash my jeans": {"washing machine"}, "eat dinner": {"table"}, "perch for a moment": {"stool", "chair"},
}


@pytest.fixture(scope="module")
def emb():
    return create_embedder("minilm")


def best(activity: str, emb) -> str | None:  # type: ignore[no-untyped-def]
    return purpose_categories(match_purpose(activity, emb))[0]


def test_a_definition_states_its_purpose():
    assert stated_purpose("a piece of furniture that provides a place to sleep") == "sleep"
    assert stated_purpose("a low seat or a stool to rest the feet of a seated person") == \
        "rest the feet of a seated person"
    assert stated_purpose("an electronic device that receives television signals") is None


def test_the_furniture_made_for_the_activity_comes_first(emb):
    # Without the stated purpose, a foot bath's "feet" made the bathtub the place to rest one's
    # feet and a sofa bed's "bed" made the sofa the place to lie down.
    assert best("rest my feet", emb) == "ottoman"
    assert best("lie down", emb) == "bed"
    assert best("lie down for a bit", emb) == "bed"
    assert best("fold my jumpers away", emb) in {"dresser", "wardrobe"}


def test_most_activities_reach_the_furniture_made_for_them(emb):
    wrong = {a: best(a, emb) for a, ok in ACTIVITIES.items() if best(a, emb) not in ok}
    # 28 of 34 with the glosses alone; 32 with the stated purpose mixed in (stated_weight).
    assert len(ACTIVITIES) - len(wrong) >= 31, wrong


def test_stated_purposes_are_part_of_the_stored_digest(emb):
    idx = GlossIndex(emb)
    assert len(idx.stated_cats) > 10 and idx.E.shape[0] == idx.n_glosses + len(idx.stated_cats)
    again = GlossIndex(emb, stored=idx.to_store())
    assert again.digest == idx.digest and (again.E == idx.E).all()


@pytest.mark.parametrize("text, activity", [
    ("where are the towels kept?", "keep the towels"),
    ("take me to where the spare bulbs are stored", "keep the spare bulbs"),
    ("where do my jumpers go", "keep my jumpers"),
    ("the thing that holds the plates", "keep the plates"),
    ("wherever the spoons live", "keep the spoons"),
    ("where can I sit", "sit"),
])
def test_what_is_kept_somewhere_is_an_activity(text, activity):
    assert find_activity(text) == activity


@pytest.mark.parametrize("text", ["go to the lamp", "where is the sofa", "the table where the keys are"])
def test_a_plain_request_names_no_activity(text):
    assert find_activity(text) is None


def test_what_is_kept_reaches_the_storage_furniture(emb):
    assert best(find_activity("where are my shirts kept"), emb) in {"wardrobe", "dresser"}
    assert best(find_activity("where do the paperbacks go"), emb) == "bookshelf"
    assert best(find_activity("the thing that holds the frozen peas"), emb) == "refrigerator"


@pytest.mark.parametrize("text, activity", [
    ("where can the children eat their lunch", "eat their lunch"),
    ("I fancy cooking an omelette", "cooking an omelette"),
    ("where could my guests hang their coats", "hang their coats"),
    ("I'd like to rest a moment, is there anything to lean on near the window", "lean on"),
])
def test_an_activity_with_any_subject_or_a_wish(text, activity):
    assert find_activity(text) == activity


def test_where_something_can_be_found_is_no_activity():
    assert find_activity("where can the remote be found") is None


def test_glosses_stored_before_stated_purposes_stay_valid(emb):
    # A map captioned before stated purposes were embedded holds only the gloss block: its
    # vectors are reused and only the stated purposes are computed (with the few rooms'
    # definitions, which are never stored).
    idx = GlossIndex(emb)
    old = {k: v for k, v in idx.to_store().items() if k != "stated"}
    calls = []

    class Counting:
        model_id, dim = emb.model_id, emb.dim

        def embed(self, texts):
            calls.append(len(texts))
            return emb.embed(texts)

    again = GlossIndex(Counting(), stored=old)  # type: ignore[arg-type]
    assert calls == [len(idx.stated_cats) + len(idx.room_names)]
    assert np.allclose(again.E, idx.E, atol=1e-6)
