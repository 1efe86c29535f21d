"""Find the vocabulary category a goal text names (for methods that only understand categories)."""

from __future__ import annotations

import re
from functools import lru_cache

from capnav.core.categories import CATEGORIES


@lru_cache(maxsize=1)
def _pattern() -> tuple[re.Pattern[str], dict[str, str]]:
    phrases = {c.name: c.name for c in CATEGORIES}
    phrases.update({s: c.name for c in CATEGORIES for s in c.synonyms})
    # longest first, so "coffee table" is read before "table" and "bar stool" before "stool"
    alts = sorted(phrases, key=len, reverse=True)
    return re.compile(r"\b(" + "|".join(re.escape(a) for a in alts) + r")s?\b"), phrases


def category_in_text(text: str) -> str | None:
    """The category of the first vocabulary phrase (name or synonym, singular or plural) in ``text``.

    "the red chair next to the sofa" -> "chair"; "go to the couch" -> "sofa"; none -> None.
    """
    pat, phrases = _pattern()
    m = pat.search(text.lower().replace("_", " "))
    return phrases[m.group(1)] if m else None
