"""The named category (the paper's type filter): its instances first, then the alternatives the
parser offered (an armchair for "chair", weighted below 1); with none in the map, every object."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from capnav.core.text import agree, article, count, join, plural
from capnav.language.context import canonical_label
from capnav.language.lexicon import load_lexicon
from capnav.retrieval.constraints.base import RankingConstraint, RankState, ranking
from capnav.retrieval.constraints.classes import coarser_classes, height_fits
from capnav.retrieval.query import ParsedQuery


@ranking
class Category(RankingConstraint):
    kind = "category"
    order = 10

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return True  # it also sets up the pool: every object when nothing is named

    def rank(self, st: RankState) -> None:
        r, q, cfg = st.r, st.q, st.r.config
        n = len(r.objects)
        weights = self.weights(st) if cfg.use_type_filter else np.zeros(n)
        st.named = q.category is not None or bool(q.category_alternatives)
        pool = np.flatnonzero(weights > 0)
        at: int | None = None  # where the count note goes
        if st.named and cfg.use_type_filter and len(pool):
            st.notes.append("")  # filled in by _count_note once the stand-ins are known
            at = len(st.notes) - 1
        else:
            if st.named and cfg.use_type_filter:
                st.notes.append("no object in the map is captioned or labelled as "
                                + join([article(c) for c in ([q.category] if q.category else
                                                             sorted(q.category_alternatives))], "or"))
            pool = np.arange(n)
            weights = np.ones(n)
        st.pool, st.weights = pool, weights
        # The detector's classes the named category is kept under when it has no class of its own.
        coarse = coarser_classes(r.cmap, q.category) if q.category is not None else set()
        if st.named and q.purpose is None and q.category is not None and cfg.use_type_filter and len(pool):
            # A stand-in serves a named category only when the named word is its hypernym in the
            # lexicon (a coffee table is a table, an armchair a chair; a table is no desk, a chair
            # no stool, a sofa no bed). A purpose names several categories and is not restricted.
            kinds = stand_ins(q) | coarse
            # What a coarser detector class holds is the category only at the category's height
            # (a coffee table's top is 0.3-0.6 m: the dining table of a COCO map is none).
            keep = np.array([st.weights[i] >= 1.0 or (r.cats[int(i)] in kinds and (
                r.cats[int(i)] not in coarse or height_fits(r.objects[int(i)], q.category))) for i in st.pool],
                dtype=bool)
            others = sorted({r.cats[int(i)] for i in st.pool[~keep]})
            st.keep(keep)
            if others:
                st.notes.append(f"{join(plural(x) for x in others)} are not a kind of "
                                f"{q.category} in the lexicon, so not considered")
        if at is not None:
            st.notes[at] = _count_note(st)
        held = bool(coarse) and any(r.cats[int(i)] in coarse for i in st.pool)
        if st.named and q.purpose is None and cfg.use_type_filter and len(pool) and not held \
                and not (weights[pool] >= 1.0).any():
            # No instance of the named category: a kind of it serves only a request whose observed
            # attributes or landmark it shows ("the round wooden table" -> a round coffee table),
            # never a bare name ("the table" is not said of the only coffee table).
            if q.shapes:
                st.keep(np.array([all(w.lower() in (r.objects[i].caption or "").lower() for w in q.shapes)
                                  for i in st.pool], dtype=bool))
            if not (q.colors or q.shapes or q.anchor_category) or not len(st.pool):
                st.refuse(self.kind, f"no {q.category or q.target_phrase} in the map, and nothing else fits "
                                     f"'{q.target_phrase}' by what was observed")
        st.group_keys.append(-st.weights[st.pool])

    @staticmethod
    def weights(st: RankState) -> NDArray[np.float64]:
        """Per object: 1 for the named category, the parser's weight for an alternative, else 0."""
        r, q = st.r, st.q
        w = np.zeros(len(r.objects))
        for cat, weight in q.category_alternatives.items():
            idx = r.of_category(canonical_label(cat))
            w[idx] = np.maximum(w[idx], float(weight))
        if q.category is not None:
            w[r.of_category(q.category)] = 1.0
        return w


def stand_ins(q: ParsedQuery) -> set[str]:
    """Categories that may answer for the named one when the map has none of it: its hyponyms in
    the lexicon (``kind_of``), and the other senses of a word of the request (a commode may be a
    dresser; a press, read as WordNet's wardrobe, may be the cupboard its synonym "closet" is).
    Not the more general categories, nor siblings: "the desk" is never the table.

    The category table wins over WordNet's tree where they disagree: WordNet files "settee" under
    "bench", but the table makes settee a sofa, and "bench" names no category, so no sofa (nor a
    bed) ever stands in for a bench."""
    lex = load_lexicon()
    out: set[str] = set()
    if q.category is not None:
        out |= {c for c, rel in lex.relations.get(q.category, {}).items() if rel.get("kind_of")}
    words = q.target_phrase.lower().split()
    for n in (1, 2, 3):
        for k in range(len(words) - n + 1):
            out |= set(lex.form_alternatives.get(" ".join(words[k:k + n]), {}))
    for w in q.text.lower().split():
        # "the kitchen press": a word read by its one furniture sense (the wardrobe) may be what
        # its synonym's first sense is ("closet": the cupboard).
        sense = next((lex.furniture_senses[f] for f in (w, w[:-1], w[:-2]) if f in lex.furniture_senses), None)
        if sense is not None and sense["category"] == q.category:
            out |= set(sense.get("alternatives", {}))
    return {canonical_label(c) for c in out}


def _count_note(st: RankState) -> str:
    """"5 armchairs are in the map, and 3 chairs could stand in" for the candidates kept."""
    q, r, w = st.q, st.r, st.weights
    tier1 = int((w[st.pool] >= 1.0).sum())
    head = count(tier1, q.category) if q.category else f"{count(tier1, 'object')} for {q.target_phrase!r}"
    alts = sorted({r.cats[int(i)] for i in st.pool if w[i] < 1.0})
    n_alt = len(st.pool) - tier1
    stand_in = count(n_alt, alts[0]) if len(alts) == 1 else \
        f"{count(n_alt, 'object')} ({join(plural(c) for c in alts)})"
    return f"{head} {agree(tier1, 'is')} in the map" + (f", and {stand_in} could stand in" if alts else "")
