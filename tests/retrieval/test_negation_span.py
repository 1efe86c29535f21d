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


@pytest.mark.parametrize(("text", "target", "excluded"), [
    ("go to the sink, not the bathtub", "sink", "bathtub"),
    ("the armchair not the sofa", "armchair", "sofa"),
    ("when you get to the bathroom go to the sink, not the bathtub", "sink", "bathtub"),
    ("take me to the chair and not the armchair", "chair", "armchair"),
])
def test_a_negated_other_kind_after_the_target_is_excluded_not_the_target(text: str, target: str,
                                                                           excluded: str) -> None:
    """"the sink, not the bathtub": the kind named first is the target; the other is excluded."""
    q = parse_instruction(text)
    assert q.category == target and any(excluded in n for n in q.negations), vars(q)


def test_a_negated_kind_alone_still_names_the_target() -> None:
    q = parse_instruction("not the black stove, the other one")
    assert q.category == "stove" and "black" in q.negations, vars(q)


def test_the_sink_not_the_bathtub_is_the_sink() -> None:
    from language.synth import grid_with_wall, make_obj, offline_retriever

    objs = [make_obj(1, "bathtub", (1.0, 1.0), (1.6, 0.8, 0.6), (240, 240, 240)),
            make_obj(2, "sink", (3.0, 1.0), (0.6, 0.5, 0.9), (240, 240, 240)),
            make_obj(3, "armchair", (6.0, 4.0), (0.8, 0.8, 0.9), (90, 60, 40)),
            make_obj(4, "chair", (7.5, 4.0), (0.5, 0.5, 0.9), (90, 60, 40))]
    r = offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.5, door=(2.5, 3.5)))
    for text, oid in (("go to the sink, not the bathtub", 2), ("take me to the chair and not the armchair", 4)):
        res = r.query(text)
        assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason
