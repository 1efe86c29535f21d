"""Requests by purpose ("somewhere to sit", "where can I wash my hands?") -> candidate categories.

Why: people often name what they want to do, not the object. The activity is compared, with the
text embedder, to what WordNet says each category is for (the lexicon's glosses: a bed "provides a
place to sleep", a washbasin is "where you can wash your hands and face"), so no hand table maps
activities to objects. The best category becomes the target; close runners-up become weighted
alternatives (a place to sit: chair, then armchair, sofa, stool).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import BY_NAME
from capnav.language.embedder import TextEmbedder
from capnav.language.lexicon import Lexicon, load_lexicon

#: A purpose clause: "somewhere (comfy) to X", "a place where I can X", "where can I X",
#: "I need to X", "something to X on". The activity is group ``act``.
_PURPOSE = [
    re.compile(r"\b(?:somewhere|someplace|some place|anywhere|a place|a spot|a surface|something|a thing)"
               r"(?:\s+\w+)?\s+(?:where\s+)?(?:(?:i|we|you|one)\s+(?:can|could|might|may)|to|for\s+(?:me\s+)?to"
               r"|for|that\s+i\s+can)\s+(?P<act>.+)"),
    re.compile(r"\bwhere\s+(?:can|could|do|should|might|would|may)\s+(?:i|we|one|you)\s+(?P<act>.+)"),
    re.compile(r"\b(?:i|we)\s*(?:'d|would)?\s*(?:need|want|like|wanna|have)\s+(?:to\s+)?(?P<act>(?!go\b|find\b|see\b"
               r"|get to\b|visit\b).+)"),
    re.compile(r"\b(?:i'm|i am|we're|we are)\s+(?P<act>(?:tired|sleepy|hungry|thirsty|cold|dirty)\b.*)"),
]
#: Words after the activity that belong to the rest of the description, not to the activity.
_TAIL = re.compile(r"\b(?:in|inside|near|next to|by|beside|close to|closest|nearest|farthest|furthest)\b.*$")
_PLACEHOLDERS = {"somewhere", "someplace", "anywhere", "place", "spot", "something", "thing", "where"}


@dataclass(frozen=True)
class PurposeMatch:
    activity: str  # "wash my hands"
    scores: dict[str, float]  # category -> cosine of the activity to its best gloss, best first


def find_activity(text: str) -> str | None:
    """The activity of a purpose request, lower case, or None when the text names none."""
    low = text.lower().strip().rstrip("?.!")
    for pat in _PURPOSE:
        m = pat.search(low)
        if m:
            act = _TAIL.sub("", m.group("act")).strip(" ,?.!")
            act = re.sub(r"^(?:please|just|quickly)\s+", "", act)
            if act and act not in _PLACEHOLDERS:
                return act
    return None


class GlossIndex:
    """Gloss embeddings of every category for one embedder (built on first use, then reused)."""

    def __init__(self, embedder: TextEmbedder, lexicon: Lexicon | None = None, max_glosses: int = 6) -> None:
        lex = lexicon or load_lexicon()
        self.embedder = embedder
        self.cats: list[str] = []
        texts: list[str] = []
        for cat, glosses in lex.glosses.items():
            names = ", ".join([cat, *BY_NAME[cat].synonyms]) if cat in BY_NAME else cat
            for g in glosses[:max_glosses]:
                self.cats.append(cat)
                texts.append(f"{names}: {g}")
        self.cats_arr = np.array(self.cats, dtype=object)
        self.E: NDArray[np.float32] = embedder.embed(texts) if texts else np.zeros((0, embedder.dim), np.float32)

    def scores(self, activity: str) -> dict[str, float]:
        q = self.embedder.embed([f"a place where you can {activity}"])[0]
        sims = self.E @ q
        best: dict[str, float] = {}
        for cat, s in zip(self.cats, sims, strict=True):
            best[cat] = max(best.get(cat, -1.0), float(s))
        return dict(sorted(best.items(), key=lambda kv: -kv[1]))


_INDEXES: dict[str, GlossIndex] = {}


def gloss_index(embedder: TextEmbedder) -> GlossIndex:
    """One gloss index per embedding model and process."""
    key = f"{embedder.model_id}@{id(embedder)}"
    if key not in _INDEXES:
        _INDEXES[key] = GlossIndex(embedder)
    return _INDEXES[key]


def match_purpose(activity: str, embedder: TextEmbedder) -> PurposeMatch:
    return PurposeMatch(activity, gloss_index(embedder).scores(activity))


def purpose_categories(match: PurposeMatch, margin: float = 0.08, min_score: float = 0.2,
                       max_alternatives: int = 4) -> tuple[str | None, dict[str, float]]:
    """(best category, alternatives with weights < 1): categories within ``margin`` of the best
    cosine, weighted by their cosine relative to the best."""
    items = list(match.scores.items())
    if not items or items[0][1] < min_score:
        return None, {}
    best_cat, best = items[0]
    alts: dict[str, float] = {}
    for cat, s in items[1:]:
        if s < best - margin or len(alts) >= max_alternatives:
            break
        alts[cat] = round(min(0.95, 0.95 * s / best), 3)
    return best_cat, alts


__all__ = ["GlossIndex", "PurposeMatch", "find_activity", "gloss_index", "match_purpose", "purpose_categories"]
