"""How goals and purposes are phrased beyond their word lists: a verb of going with its
preposition ("pop by the bath") names the goal, a clause of completion ("once you're done
there") starts the next goal, people doing something are no things kept somewhere, and the words
of an activity's object are not attributes of the furniture asked for. Sentences written for
these tests."""

from __future__ import annotations

import pytest

from capnav.language import create_embedder
from capnav.language.embedder import TextEmbedder
from capnav.language.purpose import find_activity
from capnav.retrieval.query import parse_goals, parse_instruction


@pytest.fixture(scope="module")
def emb() -> TextEmbedder:
    return create_embedder("minilm")


@pytest.mark.parametrize(("text", "goals"), [
    ("pop over by the bathtub, then the green armchair", [("bathtub", []), ("armchair", ["green"])]),
    ("could you nip by the fridge and after that go to the bed", [("refrigerator", []), ("bed", [])]),
    ("stop by the desk", [("desk", [])]),
])
def test_a_verb_of_going_with_its_preposition_names_the_goal(text, goals):
    qs = parse_goals(text)
    assert [(q.category, q.colors) for q in qs] == goals
    assert all(q.relation is None for q in qs)


def test_a_noun_before_the_preposition_is_still_the_target():
    q = parse_instruction("the ottoman by the bathtub", use_parser=False)
    assert q.category == "ottoman" and q.anchor_category == "bathtub"


@pytest.mark.parametrize("text", [
    "head to the sink, and once you have finished there go to the wardrobe",
    "go to the desk, and when you're done with that the lamp please",
])
def test_a_clause_of_completion_starts_the_next_goal(text):
    assert len(parse_goals(text)) == 2


@pytest.mark.parametrize(("text", "activity"), [
    ("where can my guests sleep tonight?", "sleep tonight"),
    ("where could the visitors sit and have a chat", "sit and have a chat"),
    ("where do the children play", "play"),
    ("where are the spoons kept", "keep the spoons"),
])
def test_people_doing_something_are_no_things_kept(text, activity):
    assert find_activity(text) == activity


@pytest.mark.parametrize(("text", "category"), [
    ("where can I chill a carton of orange juice?", "refrigerator"),
    ("somewhere to hang my blue coat", "wardrobe"),
])
def test_the_activitys_object_lends_no_attribute_to_the_furniture(emb, text, category):
    q = parse_instruction(text, emb)
    assert q.purpose and not q.colors, q
    assert q.category == category or category in q.category_alternatives, q
