"""A negation ends where its phrase ends: at a comma or semicolon ("the lamp, not the one in the
office, the one in the bedroom" excludes the office's, never the bedroom's). The reading drops
punctuation only after the negations are read (a semicolon between goals splits them first).
Sentences written for these tests, none from the development phrasings."""

from __future__ import annotations

import pytest

from capnav.retrieval.query import parse_instruction


@pytest.mark.parametrize(("text", "kept"), [
    ("the desk, not the one in the office, the one in the bedroom", "bedroom"),
    ("find the lamp, not the white one, the one by the sofa", "sofa"),
    ("the sink, not the one in the bathroom, the one in the kitchen", "kitchen"),
])
def test_a_negation_stops_at_a_comma(text: str, kept: str) -> None:
    q = parse_instruction(text, use_parser=False)
    assert q.negations and not any(kept in n for n in q.negations), vars(q)


def test_a_negation_with_no_comma_runs_to_the_end() -> None:
    q = parse_instruction("the sofa that is not in the living room", use_parser=False)
    assert any("living room" in n for n in q.negations), vars(q)
