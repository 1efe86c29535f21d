"""Find the vocabulary category a goal text names (for methods that only understand categories).

The baselines read the goal with CapNav's own instruction parser (``capnav.retrieval.query``), so
every method gets the same reading of the same words: synonyms, plurals, small typos ("lounge
chiar"), and the target rather than a landmark ("the lamp next to the sofa" is a lamp). What they
lack is what comes after: captions, attributes and predicates.
"""

from __future__ import annotations

from capnav.core.errors import InputError
from capnav.retrieval.query import parse_instruction


def category_in_text(text: str) -> str | None:
    """The target category of ``text`` (canonical vocabulary name), or None when it names none
    or is not a usable instruction (empty, not English).

    "the red chair next to the sofa" -> "chair"; "go to the couch" -> "sofa"; "the piano" -> None.
    """
    try:
        return parse_instruction(text).category
    except InputError:
        return None
