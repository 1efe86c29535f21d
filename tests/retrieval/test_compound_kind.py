"""A compound modifier whose first part, said with the object noun, is WordNet's name of a kind
of that object ("a wing-back chair": a wing chair, an armchair; "a coffee-type table": a
coffee table) names that kind: the more specific category is the target and the named one an
alternative. A compound whose first part makes no such name leaves the category alone.
Sentences written for this test (issue 22, helper lang25), none from the development phrasings
or the sets scored."""

from __future__ import annotations

import pytest

from capnav.retrieval.query import parse_instruction


@pytest.mark.parametrize(("text", "category"), [
    ("the wing-back chair by the window", "armchair"),
    ("that lovely wingbacked chair", "armchair"),
    ("go and find the coffee-type table", "coffee table"),
])
def test_the_first_part_with_the_noun_names_a_kind(text, category):
    q = parse_instruction(text)
    assert q.category == category, q
    assert q.category_alternatives, q


@pytest.mark.parametrize(("text", "category"), [
    ("the high-backed chair", "chair"),
    ("the dark-green chair", "chair"),
])
def test_other_compounds_leave_the_category(text, category):
    assert parse_instruction(text).category == category


@pytest.mark.parametrize(("text", "category"), [
    ("the wingback in the lounge", "armchair"),
    ("could you go to the wingback please", "armchair"),
])
def test_a_closed_compound_said_alone_names_the_kind_its_start_names(text, category):
    # "wingback": its start is the first word of one two-word form only (WordNet's "wing chair").
    assert parse_instruction(text).category == category


@pytest.mark.parametrize("text", ["the doohickey", "where's the thingamajig",
                                  "wandering over to the thing on the left"])
def test_an_unknown_word_with_no_such_start_names_nothing(text):
    assert parse_instruction(text).category is None
