"""A category said in an irregular plural ("the cacti", "which of the two cacti") is the category:
the lexicon takes the plurals WordNet's exception list (``noun.exc``) gives for its forms, and a
growth word's plural implies the same growth. Sentences written for this test (issue 22, helper
lang25), none from the development phrasings or the sets scored."""

from __future__ import annotations

import pytest

from capnav.language.lexicon import load_lexicon
from capnav.retrieval.query import parse_instruction


def test_the_lexicon_has_wordnets_irregular_plurals_of_its_forms():
    lex = load_lexicon()
    assert lex.forms.get("cacti") == "plant"
    assert lex.growth.get("cacti") == lex.growth.get("cactus")


@pytest.mark.parametrize(("text", "proximity"), [
    ("take me over to the cacti please", None),
    ("which of the two cacti is closest to me", "closest"),
    ("the cacti furthest from here", "farthest"),
])
def test_an_irregular_plural_names_the_category(text, proximity):
    q = parse_instruction(text)
    assert q.category == "plant", q
    assert q.proximity == proximity, q
