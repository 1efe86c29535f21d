"""The parse of an instruction: goals in order, words attached to the head, the clause of each
room, and what happens when the parser is missing or fails. Sentences written for these tests."""

from __future__ import annotations

import pytest

from capnav.core.errors import InputError
from capnav.retrieval.query import MAX_GOALS, parse_goals, parse_instruction, split_goals
from capnav.retrieval.query import parse as parse_mod

needs_spacy = pytest.mark.skipif(parse_mod.load_parser() is None, reason="spaCy's English pipeline is not installed")


# -- goal sequences (patterns: no parser needed) ---------------------------------------------------
@pytest.mark.parametrize(("text", "n"), [
    ("take me to the toilet, then to the stove", 2),
    ("the bed and after that the cabinet", 2),
    ("Visit the lamp. Afterwards the sink. Finally the ottoman", 3),
    ("the lamp between the bed and the wardrobe", 1),  # "and" alone joins landmarks, not goals
    ("I'm back from the shops. Where is the fridge?", 1),  # a piece with no object joins the next goal
    ("the lamp next to the sofa", 1),
])
def test_goals_split_at_sequence_words(text, n):
    assert len(split_goals(text)) == n


def test_goal_order_is_kept_and_each_goal_is_read_on_its_own():
    goals = parse_goals("go to the green lamp and then the grey sofa", use_parser=False)
    assert [(q.category, q.colors) for q in goals] == [("lamp", ["green"]), ("sofa", ["grey"])]


def test_more_than_five_goals_is_refused():
    text = ", then ".join(["the sofa", "the bed", "the lamp", "the stove", "the sink", "the toilet"])
    with pytest.raises(InputError, match=f"at most {MAX_GOALS}"):
        parse_goals(text, use_parser=False)
    assert len(parse_goals(", then ".join(["the sofa", "the bed", "the lamp", "the stove", "the sink"]),
                           use_parser=False)) == MAX_GOALS


def test_parse_instruction_notes_the_goals_after_the_first():
    q = parse_instruction("the wardrobe, then the bathtub", use_parser=False)
    assert q.category == "wardrobe" and any("1 more goal" in n for n in q.notes)


# -- attachment: only words attached to the head become attributes ---------------------------------
@needs_spacy
@pytest.mark.parametrize(("text", "cat"), [
    ("Whenever I am green with envy I slump into the sofa by the window", "sofa"),
    ("When the kids have been feeling blue they like to read on the bed", "bed"),
    ("I'm chuffed to bits and tickled pink, so show me the wardrobe please", "wardrobe"),
    ("could you swing round to the stove in the kitchen for me", "stove"),
])
def test_words_outside_the_head_never_become_its_attributes(text, cat):
    q = parse_instruction(text)
    assert q.category == cat
    assert not q.colors and not q.shapes, (q.colors, q.shapes)
    assert q.dropped_words and q.parser.startswith("spacy")


@needs_spacy
def test_attached_words_stay_attributes():
    q = parse_instruction("when I get home I want to flop onto the big yellow sofa next to the lamp")
    assert q.category == "sofa" and q.colors == ["yellow"] and q.size_word == "large"
    assert q.relation == "next to" and q.anchor_category == "lamp"


@needs_spacy
def test_a_negation_on_the_verb_is_kept():
    q = parse_instruction("I really do not want the white sofa, take me to the other one")
    assert q.category == "sofa" and "white" in " ".join(q.negations)


# -- the clause of each room ----------------------------------------------------------------------
@needs_spacy
@pytest.mark.parametrize(("text", "room", "origin", "side"), [
    ("stepping out of the kitchen into the hall, the plant on your left", "hallway", "kitchen", "left"),
    ("the plant on the right as you walk from the kitchen into the lounge", "living room", "kitchen", "right"),
    # a room walked through just before the one entered is where the way in starts
    ("once you come through the hallway into the office go to the desk", "office", "hallway", None),
])
def test_the_room_comes_from_the_targets_clause(text, room, origin, side):
    q = parse_instruction(text)
    assert q.room == room and q.origin_room == origin and q.side == side


# -- no parser, or a parser that fails ------------------------------------------------------------
def test_without_the_parser_an_instruction_is_read_by_patterns_with_a_note(monkeypatch):
    monkeypatch.setattr(parse_mod, "_NLP", [None])
    monkeypatch.setattr(parse_mod, "_WHY_NOT", ["spaCy is not installed"])
    q = parse_instruction("when I am back from work I would love to sit on the red armchair")
    assert q.category == "armchair" and q.parser == "patterns"
    assert any("spaCy is not installed" in n for n in q.notes)


def test_a_parser_that_fails_falls_back_with_a_note(monkeypatch):
    class Broken:
        def __init__(self) -> None:
            self.meta = {"name": "broken", "version": "0"}

        def __call__(self, text: str) -> object:
            raise ValueError("cannot read this")

    monkeypatch.setattr(parse_mod, "_NLP", [Broken()])
    q = parse_instruction("after a long day at the office I would love to lie down on the bed")
    assert q.category == "bed" and any("could not read" in n for n in q.notes)


def test_short_noun_phrases_do_not_load_the_parser():
    assert not parse_mod.needs_parse("the red chair next to the table")
    assert not parse_mod.needs_parse("somewhere to sit")
    assert parse_mod.needs_parse("the lamp, then the sofa")
    assert parse_mod.needs_parse("I need to put my feet up on the sofa")
