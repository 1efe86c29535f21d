"""Reading an instruction: its tokens and lexicon look-ups (``tokens``), its structure from a
dependency parse (``parse``: the goals in order, each goal's head object, its modifiers, its
landmark phrases with their relations and the clause each room belongs to) and the mapping of
each goal onto ``ParsedQuery`` (``mapping``), the structure retrieval reads."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.core.errors import InputError
from capnav.retrieval.query.mapping import goal_query
from capnav.retrieval.query.model import ACROSS, BETWEEN, END_OF, ROOM_WITH, ParsedQuery
from capnav.retrieval.query.parse import analyse, load_parser, needs_parse, prefetch_parser, split_goals
from capnav.retrieval.query.tokens import MAX_CHARS, MAX_WORDS, validate_instruction

if TYPE_CHECKING:
    from capnav.language.embedder import TextEmbedder

#: A request may chain this many goals ("the fridge, then the sofa, then ...").
MAX_GOALS = 5


def parse_goals(text: str, embedder: TextEmbedder | None = None, use_parser: bool | None = None
                ) -> list[ParsedQuery]:
    """Every goal of ``text`` in order (one for most instructions). ``use_parser``: None parses
    when the instruction needs it (a sentence, several goals), True always, False never. More
    than ``MAX_GOALS`` goals is an ``InputError``."""
    t = validate_instruction(text)
    goals = analyse(t, use_parser)
    if len(goals) > MAX_GOALS:
        raise InputError(f"instruction names {len(goals)} goals in a row; at most {MAX_GOALS} are supported: "
                         "split it into several requests")
    return [goal_query(g, embedder) for g in goals]


def parse_instruction(text: str, embedder: TextEmbedder | None = None, use_parser: bool | None = None
                      ) -> ParsedQuery:
    """The first goal of ``text`` (the only one for most instructions); with ``embedder`` (the
    retriever's) a request by purpose ("somewhere to sit") is mapped to categories through the
    lexicon's glosses, without one it keeps ``purpose`` and no category. A request of several
    goals notes the others (``parse_goals`` reads them all)."""
    t = validate_instruction(text)
    goals = analyse(t, use_parser)
    q = goal_query(goals[0], embedder)
    if len(goals) > 1:
        q.notes.append(f"{len(goals) - 1} more goal(s) after this one: {'; '.join(g.text for g in goals[1:])}")
    return q


__all__ = [
    "ACROSS",
    "BETWEEN",
    "END_OF",
    "MAX_CHARS",
    "MAX_GOALS",
    "MAX_WORDS",
    "ROOM_WITH",
    "ParsedQuery",
    "load_parser",
    "needs_parse",
    "parse_goals",
    "parse_instruction",
    "prefetch_parser",
    "split_goals",
    "validate_instruction",
]
