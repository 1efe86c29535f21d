"""Regional names reach their category through WordNet, not a list of regional words: a room
WordNet defines only by the fixture it is equipped with is asked for as that fixture (lavatory,
lav), and a person's name that is also such a room word (John) stays a name. Sentences written
for these tests."""

from __future__ import annotations

import pytest

from capnav.retrieval.query import parse_instruction


@pytest.mark.parametrize(("text", "category"), [
    ("is there a lavatory on this floor", "toilet"),
    ("nip to the lav for a second", "toilet"),
    ("the loo next to the bath", "toilet"),
    ("show John to the sofa", "sofa"),
])
def test_a_room_named_by_its_fixture_is_the_fixture(text, category):
    assert parse_instruction(text, use_parser=False).category == category
